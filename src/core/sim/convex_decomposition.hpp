#pragma once
// Private to norm2tex_sim: a concave mesh's collision shape as a compound of convex parts.

#include <memory>
#include <vector>

#include <btBulletCollisionCommon.h>

#include <Eigen/Core>

#include "norm2tex/mesh/textured_mesh.hpp"

namespace norm2tex {

/// HACD (hierarchical approximate convex decomposition, libbullet-extras) of `mesh`, each part
/// a convex hull about `centre` (the body origin) with `margin`. `max_concavity` is relative to
/// the mesh's size (0.02 = parts may deviate 2 % of it from convex). Returns the compound as
/// the last element; the parts before it are the compound's children, which it does not own.
/// Throws Error when HACD produces no part.
std::vector<std::unique_ptr<btCollisionShape>> decomposeConvex(const TexturedMesh& mesh,
                                                               const Eigen::Vector3d& centre,
                                                               double margin,
                                                               double max_concavity = 0.02);

}  // namespace norm2tex
