#include "sim/convex_decomposition.hpp"

#include <HACD/hacdHACD.h>

#include "norm2tex/common/error.hpp"

namespace norm2tex {

std::vector<std::unique_ptr<btCollisionShape>> decomposeConvex(const TexturedMesh& mesh,
                                                               const Eigen::Vector3d& centre,
                                                               double margin,
                                                               double max_concavity) {
  std::vector<HACD::Vec3<HACD::Real>> points;
  points.reserve(mesh.vertices().size());
  for (const Eigen::Vector3f& v : mesh.vertices()) {
    const Eigen::Vector3d p = v.cast<double>() - centre;
    points.emplace_back(p.x(), p.y(), p.z());
  }
  std::vector<HACD::Vec3<long>> triangles;
  triangles.reserve(mesh.triangles().size());
  for (const Eigen::Vector3i& t : mesh.triangles()) triangles.emplace_back(t.x(), t.y(), t.z());

  HACD::HACD hacd;
  hacd.SetPoints(points.data());
  hacd.SetNPoints(points.size());
  hacd.SetTriangles(triangles.data());
  hacd.SetNTriangles(triangles.size());
  // HACD normalises the mesh to its scale factor (1000 by default): concavity is in those units.
  hacd.SetConcavity(max_concavity * hacd.GetScaleFactor());
  hacd.SetNClusters(1);
  hacd.SetNVerticesPerCH(64);
  hacd.SetCompacityWeight(0.1);
  hacd.SetVolumeWeight(0.0);
  // Concavity is measured at sample points: with vertices alone a coarse mesh (a U of 20
  // vertices) looks convex and merges into one part; face points resolve it.
  hacd.SetAddExtraDistPoints(true);
  hacd.SetAddNeighboursDistPoints(false);
  hacd.SetAddFacesPoints(true);
  hacd.Compute();

  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  auto compound = std::make_unique<btCompoundShape>();
  btTransform identity;
  identity.setIdentity();
  for (size_t c = 0; c < hacd.GetNClusters(); ++c) {
    std::vector<HACD::Vec3<HACD::Real>> part_points(hacd.GetNPointsCH(c));
    std::vector<HACD::Vec3<long>> part_triangles(hacd.GetNTrianglesCH(c));
    if (part_points.empty() || !hacd.GetCH(c, part_points.data(), part_triangles.data())) continue;
    auto hull = std::make_unique<btConvexHullShape>();
    for (const auto& p : part_points) hull->addPoint(btVector3(p.X(), p.Y(), p.Z()), false);
    hull->recalcLocalAabb();
    hull->setMargin(margin);
    compound->addChildShape(identity, hull.get());
    shapes.push_back(std::move(hull));
  }
  if (shapes.empty()) throw Error("convex decomposition of the object mesh produced no part");
  shapes.push_back(std::move(compound));
  return shapes;
}

}  // namespace norm2tex
