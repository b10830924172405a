#pragma once

#include <utility>
#include <vector>

namespace norm2tex {

/// The DIGIT gel's compliance: total normal force on one gel [N] as a function of how deep the
/// object penetrates the undeformed gel surface [m], and back.
///
/// A table of (indentation, force) points, strictly increasing from (0, 0), interpolated
/// piecewise as a power law F = a * d^n between neighbours (exact for a Hertz-like hardening
/// gel, and linear where the two points say so); past the last point the last segment's power
/// law continues. The default is the calibrated table of Taxim-robot (a real GelSight gel, whose
/// elastomer is close to the DIGIT's): 0.493 N at 0.10 mm, 1.305 N at 0.20 mm, 3.33 N at
/// 0.40 mm, 5.94 N at 0.58 mm, a hardening close to F ~ d^1.4, continued to 2 mm along
/// the table's overall fit F = 12.85 N * (d / mm)^1.416 (34.3 N). Near zero the table starts with a
/// linear segment to 0.05 mm (the gel's first contact is linear, ~4 kN/m), so the stiffness is
/// finite at zero indentation.
class GelLaw {
 public:
  /// `points`: (indentation [m], force [N]) pairs, strictly increasing in both, the first
  /// with indentation > 0 ((0, 0) is implied). Throws Error naming `gel.law` otherwise.
  explicit GelLaw(std::vector<std::pair<double, double>> points);
  /// The default table described above.
  static GelLaw taximDefault();

  /// Force [N] at indentation `d` [m]; 0 for d <= 0.
  double force(double d) const;
  /// Indentation [m] at force `f` [N]; 0 for f <= 0. Inverse of force().
  double indentation(double f) const;
  /// force(d) / d [N/m]: the stiffness of a linear spring that gives the law's force at d
  /// (the first segment's slope at d <= 0).
  double secantStiffness(double d) const;
  /// dF/dd [N/m] at indentation `d`: n * force(d) / d on the power-law segment holding d (the
  /// first segment's slope at d <= 0). What a small extra indentation costs in force.
  double tangentStiffness(double d) const;

  const std::vector<std::pair<double, double>>& points() const { return points_; }

 private:
  // Segment i runs from points_[i - 1] (or the origin) to points_[i]: F = a_i * d^n_i.
  struct Segment {
    double d0, d1, f0, f1, a, n;
  };
  const Segment& segmentForIndentation(double d) const;
  const Segment& segmentForForce(double f) const;

  std::vector<std::pair<double, double>> points_;
  std::vector<Segment> segments_;
};

}  // namespace norm2tex
