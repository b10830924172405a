#include "norm2tex/shear/cerruti_kernel.hpp"

#include <cmath>

namespace norm2tex {
namespace {

constexpr double kPi = 3.14159265358979323846;

// a * asinh(b / |a|), which tends to 0 as a does (a ln(2|b|/|a|) -> 0).
double aAsinhBOverA(double a, double b) {
  return a == 0.0 ? 0.0 : a * std::asinh(b / std::abs(a));
}

// Antiderivatives H with d^2 H / dx dy = f, for f = x^2/r^3, y^2/r^3 and x y/r^3
// (1/r = x^2/r^3 + y^2/r^3):
//   x^2/r^3: H = y asinh(x / |y|)   (d/dx gives y / r, d/dy of that x^2 / r^3)
//   y^2/r^3: H = x asinh(y / |x|)
//   x y/r^3: H = -r
struct Antiderivatives {
  double xx, yy, xy;
};

Antiderivatives antiderivativesAt(double x, double y) {
  return {aAsinhBOverA(y, x), aAsinhBOverA(x, y), -std::hypot(x, y)};
}

}  // namespace

LateralInfluence cerrutiPointKernel(double x_mm, double y_mm, double shear_modulus_mpa) {
  const double r = std::hypot(x_mm, y_mm);
  const double scale = 1.0 / (4.0 * kPi * shear_modulus_mpa);
  const double r3 = r * r * r;
  return {scale * (1.0 / r + x_mm * x_mm / r3), scale * x_mm * y_mm / r3,
          scale * (1.0 / r + y_mm * y_mm / r3)};
}

LateralInfluence cerrutiCellInfluence(double dx_mm, double dy_mm, double cell_mm,
                                      double shear_modulus_mpa) {
  // The source point runs over the cell, so the offset (field - source) runs over
  // [dx - c/2, dx + c/2] x [dy - c/2, dy + c/2]: a rectangle integral by its four corners.
  const double h = 0.5 * cell_mm;
  const Antiderivatives a = antiderivativesAt(dx_mm + h, dy_mm + h);
  const Antiderivatives b = antiderivativesAt(dx_mm - h, dy_mm + h);
  const Antiderivatives c = antiderivativesAt(dx_mm + h, dy_mm - h);
  const Antiderivatives d = antiderivativesAt(dx_mm - h, dy_mm - h);
  const double ixx = a.xx - b.xx - c.xx + d.xx;
  const double iyy = a.yy - b.yy - c.yy + d.yy;
  const double ixy = a.xy - b.xy - c.xy + d.xy;
  const double scale = 1.0 / (4.0 * kPi * shear_modulus_mpa);
  // u_x per q_x: (1/r + x^2/r^3) = 2 x^2/r^3 + y^2/r^3.
  return {scale * (2.0 * ixx + iyy), scale * ixy, scale * (ixx + 2.0 * iyy)};
}

}  // namespace norm2tex
