#pragma once

namespace norm2tex {

/// How one tangential traction moves the gel's surface sideways, mm per unit of traction:
/// u_x = xx q_x + xy q_y, u_y = xy q_x + yy q_y (the kernel is symmetric).
struct LateralInfluence {
  double xx = 0.0;
  double xy = 0.0;
  double yy = 0.0;
};

/// Cerruti's solution for an incompressible elastic half-space (Poisson's ratio 1/2; Johnson,
/// Contact Mechanics, 1985, eq. 2.19 and 3.86): a tangential point force Q at the origin moves the
/// surface point (x, y) by u = Q / (4 pi G) (1/r + x^2 / r^3, x y / r^3) for Q along x. With
/// nu = 1/2 the force moves no surface point along z, and a normal pressure moves none sideways,
/// so a pure press leaves the gel's surface in place laterally.
///
/// The kernel for a point force (mm per N) at (x, y) mm from it, G in MPa (N/mm^2).
LateralInfluence cerrutiPointKernel(double x_mm, double y_mm, double shear_modulus_mpa);

/// The same integrated exactly over a square cell of side `cell_mm` carrying a uniform traction
/// (mm per MPa), at the field point (dx, dy) mm from the cell's centre: the closed-form
/// antiderivatives of 1/r, x^2/r^3 and x y/r^3 over a rectangle, so the cell under the field
/// point (where the point kernel is singular) is as exact as a distant one.
LateralInfluence cerrutiCellInfluence(double dx_mm, double dy_mm, double cell_mm,
                                      double shear_modulus_mpa);

}  // namespace norm2tex
