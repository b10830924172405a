#include "norm2tex/sim/contact_shear_load.hpp"

namespace norm2tex {

ShearLoad shearLoadOf(const Eigen::Vector2d& force_n, double twist_moment_nm, double friction) {
  ShearLoad load;
  load.force_n = force_n;
  load.torque_nm = twist_moment_nm;
  if (friction > 0.0) load.friction = friction;
  return load;
}

ShearLoad shearLoadOf(const GelContactState& contact, double friction) {
  return shearLoadOf(contact.shear_force_n.head<2>(), contact.twist_moment_nm, friction);
}

}  // namespace norm2tex
