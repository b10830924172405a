#pragma once
// Wavefront OBJ material libraries (.mtl), read for the one thing the package needs from them:
// which normal texture a material names, and the directory that name is relative to.
// TexturedMesh::load takes an .obj's normal texture from this reading rather than assimp's,
// because assimp's differs between releases: < 5.1 (Ubuntu 20.04 and Debian 11 ship 5.0.1)
// skips the `norm` keyword that Blender and our own saveMesh write, and 5.2 keeps the quotes
// of a quoted name and drops a map whose -o option has fewer than three numbers.

#include <string>
#include <vector>

namespace norm2tex {
namespace detail {

/// The maps of one `newmtl` block that can carry a normal texture, as the file writes their
/// file names (texture options such as `-bm 1.0` removed, surrounding quotes removed).
struct MtlMaterial {
  std::string name;
  std::string norm;  ///< `norm` (or `map_Kn`): a tangent-space normal map
  std::string bump;  ///< `map_Bump` / `bump`: what exporters use for normal maps most often
  /// The normal texture: `norm` when there is one, else `bump` (the order TexturedMesh::load
  /// takes assimp's NORMALS and HEIGHT textures in); empty when neither.
  const std::string& normalTexture() const { return norm.empty() ? bump : norm; }
};

/// The materials of an .mtl file's text, in file order. Keywords are matched case-insensitively;
/// other keywords, comments and blank lines are ignored; CRLF line ends are accepted. A map
/// line's options (`-bm 1.0`, `-o 0 0 0`, `-clamp on`, ...) are skipped and the rest of the line
/// is the file name, spaces included, as OBJ readers take it; a quoted name is unquoted.
std::vector<MtlMaterial> parseMtl(const std::string& text);

/// The material library names of an .obj file's text (`mtllib a.mtl b.mtl`), in order. Quoted
/// names are one name each; an unquoted line is split at spaces unless the whole rest of the
/// line names an existing file in `obj_directory` (names with spaces, as Blender writes them).
std::vector<std::string> parseObjMaterialLibraries(const std::string& text,
                                                   const std::string& obj_directory);

/// A material of an .obj's libraries, with the directory its texture names are relative to.
struct ObjMaterial {
  MtlMaterial material;
  std::string mtl_directory;  ///< absolute directory of the .mtl that defines it
};

/// Every material of the libraries the .obj at `obj_path` names, in library order. A library
/// that is missing or unreadable is skipped, as assimp skips it (the mesh still loads, without
/// texture). Throws Error naming the .obj when the .obj itself cannot be read.
std::vector<ObjMaterial> readObjMaterials(const std::string& obj_path);

/// The first of `materials` named `name` (its `newmtl` name), or nullptr.
const ObjMaterial* findObjMaterial(const std::vector<ObjMaterial>& materials,
                                   const std::string& name);

}  // namespace detail
}  // namespace norm2tex
