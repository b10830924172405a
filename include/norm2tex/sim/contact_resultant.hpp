#pragma once

#include <vector>

#include <Eigen/Core>

namespace norm2tex {

/// One contact point's load on a gel, in the gel frame (+z out of the gel).
struct PointLoad {
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();  ///< where it acts on the surface, x, y
  double normal_n = 0.0;  ///< normal force pressing the gel in (along -z), N
  /// Tangential force the object applies to the gel there, x, y, N.
  Eigen::Vector2d tangential_n = Eigen::Vector2d::Zero();
};

/// A contact's loads reduced to one point of the gel's surface, the pressure centre: a normal
/// force, a tangential force and a twisting moment about the gel's +z through that point.
/// (Normal forces are parallel, so about their centroid they have no moment; tangential forces
/// in the surface plane have a moment about +z only: the reduction is exact, not a fit.)
struct ContactResultant {
  double normal_n = 0.0;
  Eigen::Vector2d tangential_n = Eigen::Vector2d::Zero();
  /// The normal forces' centroid, gel frame x, y, m; without a normal force (all points at
  /// zero load) the points' plain centroid, and (0, 0) without points.
  Eigen::Vector2d pressure_centre_m = Eigen::Vector2d::Zero();
  /// Moment of the tangential forces about +z through the pressure centre, N m: positive turns
  /// +x towards +y (counter-clockwise seen from the object), as ShearLoad::torque_nm.
  double twist_moment_nm = 0.0;
};

/// Reduces `points` to their pressure centre (see ContactResultant).
ContactResultant contactResultant(const std::vector<PointLoad>& points);

}  // namespace norm2tex
