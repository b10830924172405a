#pragma once

#include <optional>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace norm2tex {

/// What the physics knows of a contact's tangential load on one gel (gel frame).
struct ShearLoad {
  /// Tangential force the object applies to the gel, x and y, N (what TactileContact's
  /// shear_force carries).
  Eigen::Vector2d force_n = Eigen::Vector2d::Zero();
  /// Twisting moment the object applies to the gel about +z through the contact's pressure
  /// centre, N m (positive: counter-clockwise seen from the object, i.e. x towards y).
  double torque_nm = 0.0;
  /// Coulomb friction coefficient between gel and object; unset: the sensor model's.
  std::optional<double> friction;
};

/// The contact's surface tractions on a grid of cells, and where the contact sticks.
struct ContactTraction {
  cv::Mat1f pressure_mpa;  ///< normal pressure per cell
  cv::Mat1f qx_mpa;        ///< tangential traction the object applies to the gel, x
  cv::Mat1f qy_mpa;        ///< and y
  cv::Mat1b stick;         ///< 255 where the contact sticks, 0 where it slips or is out of contact
  int contact_cells = 0;
  int stick_cells = 0;
  /// Fraction of the contact's area that slips (|q| = mu p): 0 in full stick, 1 in gross slip.
  double slip_fraction = 0.0;
  /// The load exceeded what friction holds (|Q| > mu P, or the moment more than the friction
  /// left can give): the whole contact slides and the traction is friction's limit.
  bool gross_slip = false;
  Eigen::Vector2d pressure_centre_mm = Eigen::Vector2d::Zero();  ///< gel frame, from the grid's origin
};

/// Normal pressure, tangential traction and the stick region of a contact from its penetration
/// (mm per cell, 0 out of contact), its normal force and its tangential load.
///
/// Pressure: p = k sqrt(d) for penetration d, k scaled so the pressures sum to the normal force.
/// For a paraboloid (a sphere's tip) pressed to a penetration profile d = delta (1 - r^2 / a^2),
/// that is Hertz's p0 sqrt(1 - r^2/a^2) exactly; for other shapes a local approximation (a flat
/// punch gets a uniform pressure instead of its rim singularity).
///
/// Translation: Cattaneo and Mindlin's partial slip by Ciavarella's and Jaeger's superposition
/// (Ciavarella 1998, Int. J. Solids Struct. 35; Jaeger 1998): q = mu (p(d) - p(d - d*)), the
/// difference between the pressure and the pressure of the same contact pressed d* less deep,
/// along the force. Where d > d* the contact sticks; d* is set by |q| summing to |Q|. For a
/// sphere this is Mindlin's solution: stick radius c / a = (1 - Q / (mu P))^(1/3).
///
/// Torsion: the twist's traction circles the pressure centre, grows with the distance r from it
/// where the contact sticks (a rigid rotation of the stuck surface) and is capped by the friction
/// the translation left, mu p - |q|, where it slips, scaled to give the moment. A local model: it
/// starts slipping at the rim, where the pressure vanishes, as Lubkin's exact solution does, but
/// is not his distribution.
///
/// |q| <= mu p holds everywhere. A load beyond friction's reach is capped and flagged gross_slip.
/// Throws Error for a non-finite or negative force, a non-finite load, or a friction <= 0.
ContactTraction solveContactTraction(const cv::Mat1f& penetration_mm, double cell_mm,
                                     double normal_force_n, const ShearLoad& load,
                                     double friction);

}  // namespace norm2tex
