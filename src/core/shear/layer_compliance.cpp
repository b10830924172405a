#include "norm2tex/shear/layer_compliance.hpp"

#include <cmath>

#include <Eigen/Dense>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The layer's k h beyond which it is a half-space to double precision's taste (e^-2kh < 1e-13).
constexpr double kDeepLayer = 15.0;

// Stream function psi(z) = a cosh(kz) + b sinh(kz) + c z cosh(kz) + e z sinh(kz) over the layer
// z in [-h, 0] (u = psi', w = -i k psi, times e^{ikx}); row n of the result holds the n-th
// derivative of each basis function at z.
Eigen::Matrix<double, 4, 4> basisDerivatives(double k, double z) {
  const double ch = std::cosh(k * z), sh = std::sinh(k * z);
  Eigen::Matrix<double, 4, 4> m;
  // cosh, sinh: derivatives alternate k^n sinh / cosh.
  m(0, 0) = ch;            m(0, 1) = sh;
  m(1, 0) = k * sh;        m(1, 1) = k * ch;
  m(2, 0) = k * k * ch;    m(2, 1) = k * k * sh;
  m(3, 0) = k * k * k * sh; m(3, 1) = k * k * k * ch;
  // z cosh(kz): d^n = z k^n (cosh|sinh) + n k^(n-1) (sinh|cosh).
  m(0, 2) = z * ch;
  m(1, 2) = z * k * sh + ch;
  m(2, 2) = z * k * k * ch + 2 * k * sh;
  m(3, 2) = z * k * k * k * sh + 3 * k * k * ch;
  m(0, 3) = z * sh;
  m(1, 3) = z * k * ch + sh;
  m(2, 3) = z * k * k * sh + 2 * k * ch;
  m(3, 3) = z * k * k * k * ch + 3 * k * k * sh;
  return m;
}

}  // namespace

LayerCompliance layerCompliance(double k, double h) {
  if (!(k > 0.0) || !(h > 0.0)) throw Error("layerCompliance: k and h must be > 0");
  LayerCompliance c;
  if (k * h > kDeepLayer) return {1.0 / k, 0.5 / k};
  c.transverse = std::tanh(k * h) / k;
  if (k * h < 1e-4) {  // the simple shear of a thin layer; the basis degenerates as k -> 0
    c.longitudinal = h;
    return c;
  }
  // Incompressible plane strain (G = 1): sigma_xz = psi'' + k^2 psi,
  // sigma_zz = (i/k)(psi''' - 3 k^2 psi'). Base z = -h: psi = psi' = 0 (bonded). Surface z = 0:
  // sigma_xz = 1, sigma_zz = 0. The surface's tangential displacement is psi'(0).
  const Eigen::Matrix<double, 4, 4> base = basisDerivatives(k, -h);
  const Eigen::Matrix<double, 4, 4> top = basisDerivatives(k, 0.0);
  Eigen::Matrix4d a;
  a.row(0) = base.row(0);
  a.row(1) = base.row(1);
  a.row(2) = top.row(2) + k * k * top.row(0);
  a.row(3) = top.row(3) - 3 * k * k * top.row(1);
  const Eigen::Vector4d rhs(0.0, 0.0, 1.0, 0.0);
  const Eigen::Vector4d coefficients = a.fullPivLu().solve(rhs);
  c.longitudinal = top.row(1).dot(coefficients);
  return c;
}

void LayerCorrection::at(double r_mm, double& s_out, double& d_out) const {
  const double u = r_mm / step_mm;
  const size_t last = s.size() - 1;
  if (u >= static_cast<double>(last)) {
    s_out = s[last];
    d_out = d[last];
    return;
  }
  const size_t i = static_cast<size_t>(u);
  const double f = u - static_cast<double>(i);
  s_out = (1 - f) * s[i] + f * s[i + 1];
  d_out = (1 - f) * d[i] + f * d[i + 1];
}

LayerCorrection layerCorrection(double h, double reach_mm) {
  if (!(h > 0.0) || !(reach_mm > 0.0)) throw Error("layerCorrection: h and reach must be > 0");
  // The correction varies over the layer's thickness: 1/40 of it interpolates to ~1e-4.
  LayerCorrection out;
  out.step_mm = h / 40.0;
  const size_t entries = static_cast<size_t>(std::ceil(reach_mm / out.step_mm)) + 2;
  // The integrands (dC k) are smooth and fall as e^{-2kh}: up to k h = 15; Simpson's rule with
  // steps small against the Bessel functions' period at the largest r.
  const double k_max = kDeepLayer / h;
  const double r_max = out.step_mm * static_cast<double>(entries - 1);
  int steps = static_cast<int>(std::ceil(k_max * r_max / 0.15));
  steps = std::max(400, steps + (steps % 2));
  const double dk = k_max / steps;
  std::vector<double> sum_part(steps + 1), diff_part(steps + 1), weight(steps + 1);
  for (int n = 0; n <= steps; ++n) {
    const double k = n * dk;
    double dct_k, dcl_k;  // (layer - half-space) compliance times k
    if (n == 0) {
      dct_k = -1.0;  // tanh(kh) - 1 at k = 0
      dcl_k = -0.5;  // k h - 1/2
    } else {
      const LayerCompliance c = layerCompliance(k, h);
      dct_k = c.transverse * k - 1.0;
      dcl_k = c.longitudinal * k - 0.5;
    }
    sum_part[n] = 0.5 * (dct_k + dcl_k);
    diff_part[n] = 0.5 * (dcl_k - dct_k);
    weight[n] = (n == 0 || n == steps) ? 1.0 : (n % 2 ? 4.0 : 2.0);
  }
  out.s.resize(entries);
  out.d.resize(entries);
  for (size_t i = 0; i < entries; ++i) {
    const double r = out.step_mm * static_cast<double>(i);
    double s = 0.0, d = 0.0;
    for (int n = 0; n <= steps; ++n) {
      const double x = n * dk * r;
      const double j0 = ::j0(x);
      // J2 = (2 / x) J1 - J0, with its small-argument limit x^2 / 8.
      const double j2 = x < 1e-3 ? x * x / 8.0 : 2.0 / x * ::j1(x) - j0;
      s += weight[n] * sum_part[n] * j0;
      d += weight[n] * diff_part[n] * j2;
    }
    out.s[i] = s * dk / 3.0 / (2.0 * kPi);
    out.d[i] = -d * dk / 3.0 / (2.0 * kPi);
  }
  return out;
}

}  // namespace norm2tex
