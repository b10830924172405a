#pragma once

#include "norm2tex/mesh/textured_mesh.hpp"

namespace norm2tex {

/// A UV sphere centred on the origin, radius in metres. UVs are equirectangular (u = longitude,
/// v = latitude from the south pole at v = 0), one seam. `rings` >= 3, `segments` >= 3.
TexturedMesh makeUvSphere(double radius_m, int rings = 48, int segments = 96);

/// An axis-aligned box centred on the origin, size in metres. Each face has its own 4 vertices
/// and maps UV [0, 1]^2 scaled by the face's size relative to `uv_period_m` (so a texture tiles
/// at the same millimetre scale on every face; 0 = each face maps [0, 1]^2 once).
TexturedMesh makeBox(const Eigen::Vector3d& size_m, double uv_period_m = 0.0);

}  // namespace norm2tex
