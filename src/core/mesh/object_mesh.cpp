#include "norm2tex/mesh/object_mesh.hpp"

#include <cmath>
#include <sstream>

#include "norm2tex/common/error.hpp"
#include "norm2tex/mesh/mesh_primitives.hpp"

namespace norm2tex {
namespace {

// A loaded box has every vertex on a corner of its bounds (duplicated per face for UVs) and
// uses all 8 corners (4 corners alone can make a tetrahedron).
bool isBoundingBox(const TexturedMesh& mesh) {
  const Eigen::AlignedBox3f& box = mesh.bounds();
  const float tolerance = 1e-4f * box.diagonal().norm();
  unsigned corners_used = 0;  // bit k: corner k (x, y, z at max = bits 0, 1, 2)
  for (const Eigen::Vector3f& v : mesh.vertices()) {
    int corner = 0;
    for (int axis = 0; axis < 3; ++axis) {
      if (std::abs(v[axis] - box.max()[axis]) <= tolerance) {
        corner |= 1 << axis;
      } else if (std::abs(v[axis] - box.min()[axis]) > tolerance) {
        return false;
      }
    }
    corners_used |= 1u << corner;
  }
  return corners_used == 0xFFu;
}

}  // namespace

ObjectMesh loadObjectMesh(const std::string& spec, double scale) {
  ObjectMesh out;
  if (spec.rfind("sphere:", 0) == 0) {
    std::istringstream text(spec.substr(7));
    double radius_mm = 0;
    if (!(text >> radius_mm) || !(radius_mm > 0) || !text.eof()) {
      throw Error("object mesh '" + spec + "': a sphere is sphere:<radius_mm> with radius > 0");
    }
    out.mesh = makeUvSphere(radius_mm * 1e-3, 96, 192);
    return out;
  }
  if (spec.rfind("box:", 0) == 0) {
    double x = 0, y = 0, z = 0;
    char sep1 = 0, sep2 = 0;
    std::istringstream sizes(spec.substr(4));
    if (!(sizes >> x >> sep1 >> y >> sep2 >> z) || sep1 != 'x' || sep2 != 'x' || !(x > 0) ||
        !(y > 0) || !(z > 0) || !sizes.eof()) {
      throw Error("object mesh '" + spec + "': a box is box:<x_mm>x<y_mm>x<z_mm>, sizes > 0");
    }
    out.mesh = makeBox(Eigen::Vector3d(x, y, z) * 1e-3, 0.02);
    out.shape = ObjectMesh::Shape::kBox;
    return out;
  }
  MeshLoadOptions options;
  options.scale = scale;
  out.mesh = TexturedMesh::load(spec, options);
  if (isBoundingBox(out.mesh)) out.shape = ObjectMesh::Shape::kBox;
  return out;
}

}  // namespace norm2tex
