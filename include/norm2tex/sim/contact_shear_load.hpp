#pragma once

#include "norm2tex/shear/contact_traction.hpp"
#include "norm2tex/sim/gripper_sim.hpp"

namespace norm2tex {

/// The tangential load a gel's contact puts on the renderer's shear stage: the physics'
/// tangential force on the gel (gel frame x, y) and the object's friction.
inline ShearLoad shearLoadOf(const GelContactState& contact, double friction) {
  ShearLoad load;
  load.force_n = contact.shear_force_n.head<2>();
  load.friction = friction;
  return load;
}

}  // namespace norm2tex
