#pragma once

#include <vector>

namespace norm2tex {

/// The surface compliance of an incompressible elastic layer of thickness h bonded to a rigid
/// base (the gel on its acrylic window) to a tangential traction of wavenumber k, per unit of
/// the shear modulus G (mm per MPa times G): the displacement's amplitude over the traction's.
/// `transverse`: traction across k (an antiplane wave): tanh(k h) / k, exactly.
/// `longitudinal`: traction along k (plane strain, the surface free of normal traction): from
/// the biharmonic stream function's four constants, fixed by the base's grip and the surface's
/// tractions, solved numerically. Both tend to the half-space's 1/k and 1/(2 k) when k h >> 1
/// and to the layer's simple shear, h, when k h << 1.
struct LayerCompliance {
  double transverse = 0.0;
  double longitudinal = 0.0;
};
LayerCompliance layerCompliance(double k_per_mm, double thickness_mm);

/// What the layer takes away from Cerruti's half-space kernel, as radial profiles for G = 1:
/// the kernel's change is S(r) I + D(r) (2 r^ r^T - I) (r^ the unit offset), with
/// S(r) = 1/(2 pi) int (dCt + dCl)/2 k J0(k r) dk and D(r) = -1/(2 pi) int (dCl - dCt)/2 k
/// J2(k r) dk, dC the layer's compliance minus the half-space's (smooth: the layer differs only
/// at wavelengths beyond its thickness). Tabulated at `step_mm` from 0 to `reach_mm`.
struct LayerCorrection {
  double step_mm = 0.0;
  std::vector<double> s;  ///< mm per MPa at G = 1 MPa ...
  std::vector<double> d;  ///< ... both to be divided by G
  /// Linear interpolation of the profiles at r (beyond the table: its last entry).
  void at(double r_mm, double& s_out, double& d_out) const;
};
LayerCorrection layerCorrection(double thickness_mm, double reach_mm);

}  // namespace norm2tex
