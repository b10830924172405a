#pragma once

#include <string>

#include <Eigen/Core>

#include "norm2tex/mesh/textured_mesh.hpp"

namespace norm2tex {

/// A render mesh plus what is known of its exact shape, for physics that wants exact
/// primitives where it can have them.
struct ObjectMesh {
  enum class Shape { kMesh, kBox, kSphere, kCylinder, kCapsule };
  TexturedMesh mesh;
  /// kBox: the mesh is its bounding box (mesh.bounds()). kSphere, kCylinder, kCapsule: every
  /// vertex lies on that primitive (within 1e-4 of the bounds' diagonal), centred in the
  /// bounds with its axis along the file's `axis`.
  Shape shape = Shape::kMesh;
  int axis = 2;                ///< kCylinder, kCapsule: 0 = x, 1 = y, 2 = z
  double radius_m = 0.0;       ///< kSphere, kCylinder, kCapsule
  double half_length_m = 0.0;  ///< kCylinder: half its height; kCapsule: half its spine
};

/// "mesh", "box", "sphere", "cylinder", "capsule".
const char* shapeName(ObjectMesh::Shape shape);

/// `spec` is a mesh file (OBJ, STL, PLY, DAE, glTF/GLB; `scale` converts its units to metres)
/// or a primitive in millimetres: "box:<x>x<y>x<z>" (UVs tile every 20 mm on every face) or
/// "sphere:<radius>" (a 96 x 192 UV sphere). A file is reported as a box when its vertices all lie
/// on the corners of its bounding box, as a sphere, an axis-aligned cylinder or capsule when
/// they all lie on one (a tessellated cylinder needs 16 or more distinct rim vertices). Throws
/// Error naming the file, or the spec and its valid form.
ObjectMesh loadObjectMesh(const std::string& spec, double scale = 1.0);

/// Whether `spec` names a primitive ("box:...", "sphere:...") rather than a mesh file.
bool isPrimitiveMeshSpec(const std::string& spec);

}  // namespace norm2tex
