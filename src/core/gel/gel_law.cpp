#include "norm2tex/gel/gel_law.hpp"

#include <cmath>
#include <sstream>

#include "norm2tex/common/error.hpp"

namespace norm2tex {

GelLaw::GelLaw(std::vector<std::pair<double, double>> points) : points_(std::move(points)) {
  if (points_.empty()) throw Error("gel.law: needs at least one (indentation, force) point");
  double d_prev = 0.0, f_prev = 0.0;
  for (std::size_t i = 0; i < points_.size(); ++i) {
    const auto [d, f] = points_[i];
    if (!(std::isfinite(d) && std::isfinite(f) && d > d_prev && f > f_prev)) {
      std::ostringstream message;
      message << "gel.law: point " << i << " (" << d * 1e3 << " mm, " << f
              << " N) must be finite and strictly greater than the previous point in both "
                 "indentation and force (the first point > (0, 0))";
      throw Error(message.str());
    }
    Segment s{d_prev, d, f_prev, f, 0.0, 1.0};
    if (i == 0) {
      s.a = f / d;  // linear from the origin: finite stiffness at first touch
    } else {
      s.n = std::log(f / f_prev) / std::log(d / d_prev);
      s.a = f_prev / std::pow(d_prev, s.n);
    }
    segments_.push_back(s);
    d_prev = d;
    f_prev = f;
  }
}

GelLaw GelLaw::taximDefault() {
  return GelLaw({{0.05e-3, 0.2},
                 {0.10e-3, 0.493},
                 {0.20e-3, 1.305},
                 {0.40e-3, 3.33},
                 {0.58e-3, 5.94},
                 {2.00e-3, 34.3}});
}

const GelLaw::Segment& GelLaw::segmentForIndentation(double d) const {
  for (const Segment& s : segments_) {
    if (d <= s.d1) return s;
  }
  return segments_.back();
}

const GelLaw::Segment& GelLaw::segmentForForce(double f) const {
  for (const Segment& s : segments_) {
    if (f <= s.f1) return s;
  }
  return segments_.back();
}

double GelLaw::force(double d) const {
  if (!(d > 0.0)) return 0.0;
  const Segment& s = segmentForIndentation(d);
  return s.a * std::pow(d, s.n);
}

double GelLaw::indentation(double f) const {
  if (!(f > 0.0)) return 0.0;
  const Segment& s = segmentForForce(f);
  return std::pow(f / s.a, 1.0 / s.n);
}

double GelLaw::secantStiffness(double d) const {
  if (!(d > 0.0)) return segments_.front().a;
  return force(d) / d;
}

double GelLaw::tangentStiffness(double d) const {
  if (!(d > 0.0)) return segments_.front().a;
  return segmentForIndentation(d).n * force(d) / d;
}

}  // namespace norm2tex
