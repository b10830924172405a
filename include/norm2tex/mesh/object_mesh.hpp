#pragma once

#include <string>

#include <Eigen/Core>

#include "norm2tex/mesh/textured_mesh.hpp"

namespace norm2tex {

/// A render mesh plus what is known of its exact shape, for physics that wants exact
/// primitives where it can have them.
struct ObjectMesh {
  enum class Shape { kMesh, kBox, kSphere };
  TexturedMesh mesh;
  Shape shape = Shape::kMesh;
  Eigen::Vector3d box_size_m = Eigen::Vector3d::Zero();  ///< kBox: full edge lengths, metres
  double sphere_radius_m = 0.0;                          ///< kSphere: radius, metres
};

/// `spec` is a mesh file (OBJ, STL, PLY, DAE, glTF/GLB; `scale` converts its units to metres)
/// or a primitive in millimetres: "box:<x>x<y>x<z>" (UVs tile every 20 mm on every face) or
/// "sphere:<radius>" (a 96 x 192 UV sphere). A file whose vertices all lie on the corners of
/// its bounding box, or all at one distance from their centroid (within 0.5 %), is reported as
/// a box or a sphere too. Throws Error naming the file, or the spec and its valid form.
ObjectMesh loadObjectMesh(const std::string& spec, double scale = 1.0);

}  // namespace norm2tex
