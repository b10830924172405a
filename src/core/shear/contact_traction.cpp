#include "norm2tex/shear/contact_traction.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

// At most this many steps of d*'s search (Newton's converge in a handful).
constexpr int kMaxStickDepthSteps = 40;

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

// The d* at which the slip annulus carries `target` = Q / (mu k A):
// S(d*) = sum of sqrt(d) - sqrt(max(d - d*, 0)) grows from 0 at d* = 0 to sum sqrt(d) at the
// deepest d, convex in d*: from its first step on Newton's approaches the root from above,
// and a bracket falls back to halving should a step leave it. A handful of sums instead of
// bisection's thirty.
double stickDepth(const std::vector<ContactCell>& cells, double target, double deepest) {
  double low = 0.0, high = deepest;
  double ds = 0.0;
  for (int i = 0; i < kMaxStickDepthSteps; ++i) {
    double sum = 0.0, slope = 0.0;
    for (const ContactCell& c : cells) {
      const double rest = c.depth - ds;
      if (rest > 0.0) {
        const double root = std::sqrt(rest);
        sum += c.root - root;
        slope += 0.5 / root;
      } else {
        sum += c.root;
      }
    }
    const double miss = sum - target;
    if (std::abs(miss) <= 1e-10 * target) break;
    (miss < 0.0 ? low : high) = ds;
    const double newton = slope > 0.0 ? ds - miss / slope : high;
    ds = (newton > low && newton < high) ? newton : 0.5 * (low + high);
  }
  return ds;
}

// The twist's stiffness kappa for which sum of min(kappa r, left) r = target (moment per cell
// area). The sum is piecewise linear in kappa, bending where kappa = left / r: sorted by that
// knee, it is solved exactly in one pass.
double twistStiffness(const std::vector<double>& radius, const std::vector<double>& left,
                      double target) {
  std::vector<std::pair<double, size_t>> knees;
  double linear = 0.0;  // sum of r^2 over cells still below their cap
  for (size_t n = 0; n < radius.size(); ++n) {
    if (radius[n] <= 0.0 || left[n] <= 0.0) continue;
    knees.emplace_back(left[n] / radius[n], n);
    linear += radius[n] * radius[n];
  }
  std::sort(knees.begin(), knees.end());
  double capped = 0.0;  // sum of left r over cells at their cap
  for (const auto& [knee, n] : knees) {
    // Below this knee: moment(kappa) = kappa linear + capped.
    if (knee * linear + capped >= target) return (target - capped) / linear;
    linear -= radius[n] * radius[n];
    capped += left[n] * radius[n];
  }
  return knees.empty() ? 0.0 : knees.back().first;
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
    d_star = stickDepth(cells, q_mag / (friction * k * area), deepest);
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
    std::vector<double> left(cells.size());  // the friction the translation left, MPa
    double capacity = 0.0;                    // the moment that friction can give, N mm
    double kappa_high = 0.0;
    for (size_t n = 0; n < cells.size(); ++n) {
      radius[n] = (cells[n].where - out.pressure_centre_mm).norm();
      left[n] = friction * k * cells[n].root - translation[n];
      capacity += left[n] * radius[n] * area;
      if (radius[n] > 0.0) kappa_high = std::max(kappa_high, left[n] / radius[n]);
    }
    if (moment >= capacity) {
      twist_slides = true;
      out.gross_slip = true;
      kappa = kappa_high;
    } else {
      kappa = twistStiffness(radius, left, moment / area);
    }
    for (size_t n = 0; n < cells.size(); ++n) twist[n] = std::min(kappa * radius[n], left[n]);
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
