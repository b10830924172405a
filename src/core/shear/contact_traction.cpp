#include "norm2tex/shear/contact_traction.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

// Enough halvings to pin d* and the twist's stiffness to a few parts in 1e9 of their range.
constexpr int kBisections = 32;

struct ContactCell {
  int index;              // into the grid, row-major
  double depth;           // penetration, mm
  double root;            // sqrt(depth)
  Eigen::Vector2d where;  // cell centre, mm from the grid's origin
};

void requireLoad(double normal_force_n, const ShearLoad& load, double friction) {
  if (!(std::isfinite(normal_force_n) && normal_force_n >= 0.0)) {
    throw Error("contact traction: normal force = " + std::to_string(normal_force_n) +
                " N is not valid; valid: a finite force >= 0 N");
  }
  if (!load.force_n.allFinite() || !std::isfinite(load.torque_nm)) {
    throw Error("contact traction: the tangential force and moment must be finite");
  }
  if (!(std::isfinite(friction) && friction > 0.0)) {
    throw Error("contact traction: friction = " + std::to_string(friction) +
                " is not valid; valid: a finite coefficient > 0");
  }
}

// Smallest x in [0, high] with increasing(x) >= target, by bisection.
template <typename F>
double bisect(F increasing, double target, double high) {
  double low = 0.0;
  for (int i = 0; i < kBisections; ++i) {
    const double mid = 0.5 * (low + high);
    (increasing(mid) < target ? low : high) = mid;
  }
  return 0.5 * (low + high);
}

}  // namespace

ContactTraction solveContactTraction(const cv::Mat1f& penetration_mm, double cell_mm,
                                     double normal_force_n, const ShearLoad& load,
                                     double friction) {
  requireLoad(normal_force_n, load, friction);
  if (!(cell_mm > 0.0)) throw Error("contact traction: the cell size must be > 0 mm");
  ContactTraction out;
  out.pressure_mpa = cv::Mat1f::zeros(penetration_mm.size());
  out.qx_mpa = cv::Mat1f::zeros(penetration_mm.size());
  out.qy_mpa = cv::Mat1f::zeros(penetration_mm.size());
  out.stick = cv::Mat1b::zeros(penetration_mm.size());

  std::vector<ContactCell> cells;
  double root_sum = 0.0;
  double deepest = 0.0;
  for (int i = 0; i < penetration_mm.rows; ++i) {
    for (int j = 0; j < penetration_mm.cols; ++j) {
      const double d = penetration_mm(i, j);
      if (!(d > 0.0)) continue;
      cells.push_back({i * penetration_mm.cols + j, d, std::sqrt(d),
                       {(j + 0.5) * cell_mm, (i + 0.5) * cell_mm}});
      root_sum += cells.back().root;
      deepest = std::max(deepest, d);
    }
  }
  out.contact_cells = static_cast<int>(cells.size());
  if (cells.empty() || normal_force_n == 0.0) return out;

  const double area = cell_mm * cell_mm;
  const double k = normal_force_n / (area * root_sum);  // MPa per sqrt(mm)
  float* pressure = out.pressure_mpa.ptr<float>();
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (const ContactCell& c : cells) {
    pressure[c.index] = static_cast<float>(k * c.root);
    centre += c.root * c.where;
  }
  out.pressure_centre_mm = centre / root_sum;

  // Translation (Ciavarella-Jaeger): q = mu k (sqrt(d) - sqrt(max(d - d*, 0))) along Q.
  const double q_mag = load.force_n.norm();
  const double q_limit = friction * normal_force_n;
  const Eigen::Vector2d along = q_mag > 0.0 ? Eigen::Vector2d(load.force_n / q_mag)
                                            : Eigen::Vector2d::Zero();
  double d_star = 0.0;
  if (q_mag >= q_limit) {
    out.gross_slip = true;
    d_star = deepest;
  } else if (q_mag > 0.0) {
    const auto carried = [&](double ds) {
      double sum = 0.0;
      for (const ContactCell& c : cells) sum += c.root - std::sqrt(std::max(c.depth - ds, 0.0));
      return friction * k * area * sum;
    };
    d_star = bisect(carried, q_mag, deepest);
  }
  std::vector<double> translation(cells.size());
  for (size_t n = 0; n < cells.size(); ++n) {
    const ContactCell& c = cells[n];
    translation[n] = friction * k * (c.root - std::sqrt(std::max(c.depth - d_star, 0.0)));
  }

  // Torsion: min(kappa r, mu p - |q_translation|) around the pressure centre.
  std::vector<double> twist(cells.size(), 0.0);
  std::vector<double> radius(cells.size());
  const double moment = std::abs(load.torque_nm) * 1e3;  // N mm
  double kappa = 0.0;
  bool twist_slides = false;
  if (moment > 0.0) {
    double capacity = 0.0;  // the moment friction can still give, N mm
    double kappa_high = 0.0;
    for (size_t n = 0; n < cells.size(); ++n) {
      radius[n] = (cells[n].where - out.pressure_centre_mm).norm();
      const double left = friction * k * cells[n].root - translation[n];
      capacity += left * radius[n] * area;
      if (radius[n] > 0.0) kappa_high = std::max(kappa_high, left / radius[n]);
    }
    const auto given = [&](double kap) {
      double sum = 0.0;
      for (size_t n = 0; n < cells.size(); ++n) {
        const double left = friction * k * cells[n].root - translation[n];
        sum += std::min(kap * radius[n], left) * radius[n];
      }
      return sum * area;
    };
    if (moment >= capacity) {
      twist_slides = true;
      out.gross_slip = true;
      kappa = kappa_high;
    } else {
      kappa = bisect(given, moment, kappa_high);
    }
    for (size_t n = 0; n < cells.size(); ++n) {
      const double left = friction * k * cells[n].root - translation[n];
      twist[n] = std::min(kappa * radius[n], left);
    }
  }

  const double turn = load.torque_nm >= 0.0 ? 1.0 : -1.0;
  float* qx = out.qx_mpa.ptr<float>();
  float* qy = out.qy_mpa.ptr<float>();
  std::uint8_t* stick = out.stick.ptr<std::uint8_t>();
  for (size_t n = 0; n < cells.size(); ++n) {
    const ContactCell& c = cells[n];
    Eigen::Vector2d q = translation[n] * along;
    if (twist[n] > 0.0 && radius[n] > 0.0) {
      const Eigen::Vector2d r = c.where - out.pressure_centre_mm;
      q += turn * twist[n] / radius[n] * Eigen::Vector2d(-r.y(), r.x());
    }
    qx[c.index] = static_cast<float>(q.x());
    qy[c.index] = static_cast<float>(q.y());
    const bool translation_sticks = !out.gross_slip && c.depth > d_star;
    const bool twist_sticks =
        moment == 0.0 ||
        (!twist_slides && kappa * radius[n] < friction * k * c.root - translation[n]);
    if (translation_sticks && twist_sticks) {
      stick[c.index] = 255;
      ++out.stick_cells;
    }
  }
  out.slip_fraction = 1.0 - static_cast<double>(out.stick_cells) / out.contact_cells;
  return out;
}

}  // namespace norm2tex
