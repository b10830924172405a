#pragma once

#include <Eigen/Core>

#include "norm2tex/shear/contact_traction.hpp"
#include "norm2tex/sim/gripper_sim.hpp"

namespace norm2tex {

/// The tangential load of a gel's contact as the shear stage takes it (ShearField through the
/// renderer, ContactPatchMeter): the tangential force on the gel (gel frame x, y, N), the
/// twisting moment about its +z (N m) and the object's friction coefficient. A friction <= 0 (a
/// frictionless scene, whose contacts carry no tangential load, or one not known) is left unset:
/// the shear stage then takes the sensor model's, as it needs one > 0.
ShearLoad shearLoadOf(const Eigen::Vector2d& force_n, double twist_moment_nm, double friction);

/// The same from what the physics measured on a gel: its shear force and twisting moment.
ShearLoad shearLoadOf(const GelContactState& contact, double friction);

}  // namespace norm2tex
