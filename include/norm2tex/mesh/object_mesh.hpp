#pragma once

#include <string>

#include <Eigen/Core>

#include "norm2tex/mesh/textured_mesh.hpp"

namespace norm2tex {

/// A render mesh plus what is known of its exact shape, for physics that wants exact
/// primitives where it can have them.
struct ObjectMesh {
  enum class Shape { kMesh, kBox };
  TexturedMesh mesh;
  Shape shape = Shape::kMesh;  ///< kBox: the mesh is its bounding box (mesh.bounds())
};

/// `spec` is a mesh file (OBJ, STL, PLY, DAE, glTF/GLB; `scale` converts its units to metres)
/// or a primitive in millimetres: "box:<x>x<y>x<z>" (UVs tile every 20 mm on every face) or
/// "sphere:<radius>" (a 96 x 192 UV sphere). A file whose vertices all lie on the corners of
/// its bounding box is reported as a box too. (Spheres get no exact shape:
/// Bullet's single-point sphere contact does not hold a pinched ball, see GripperSim.) Throws Error
/// naming the file, or the spec and its valid form.
ObjectMesh loadObjectMesh(const std::string& spec, double scale = 1.0);

}  // namespace norm2tex
