// TexturedMesh::load: assimp import, scene-graph flattening and normal texture lookup. Kept
// apart from textured_mesh.cpp so only this file depends on assimp.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <unordered_set>
#include <utility>
#include <vector>

#include <assimp/config.h>
#include <assimp/material.h>
#include <assimp/mesh.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>

#include "mesh/gltf_writer.hpp"
#include "mesh/mtl_file.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/mesh/textured_mesh.hpp"

namespace norm2tex {
namespace {

namespace fs = std::filesystem;

Eigen::Matrix4d toEigen(const aiMatrix4x4& m) {
  Eigen::Matrix4d result;
  result << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2,
      m.d3, m.d4;
  return result;
}

// assimp reports its errors over several lines; an Error message is one line.
std::string oneLine(std::string text) {
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text.empty() ? "unknown error" : text;
}

// The material's normal texture: NORMALS (glTF normalTexture, OBJ norm) first, then HEIGHT
// (OBJ map_Bump / bump, which assimp files under HEIGHT). Empty when there is none.
std::string normalTextureOf(const aiMaterial* material) {
  if (material == nullptr) return {};
  for (aiTextureType type : {aiTextureType_NORMALS, aiTextureType_HEIGHT}) {
    aiString name;
    if (material->GetTextureCount(type) > 0 &&
        material->GetTexture(type, 0, &name) == aiReturn_SUCCESS && name.length > 0) {
      return name.C_Str();
    }
  }
  return {};
}

bool isObjFile(const std::string& path) {
  std::string extension = fs::path(path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return extension == ".obj";
}

// A material's name as assimp read it (OBJ: its newmtl name).
std::string materialName(const aiMaterial* material) {
  aiString name;
  if (material == nullptr || material->Get(AI_MATKEY_NAME, name) != aiReturn_SUCCESS) return {};
  return name.C_Str();
}

// A texture reference made absolute. `directories` are where a relative reference may be
// relative to, most likely first (for an .obj: its .mtl's directory, then its own); the first
// where the file exists wins, else the first. Embedded textures ("*0", data URIs) have no
// file: empty.
std::string resolveTexture(const std::string& reference, const aiScene& scene,
                           const std::vector<fs::path>& directories) {
  if (reference.empty() || reference[0] == '*' || reference.rfind("data:", 0) == 0 ||
      scene.GetEmbeddedTexture(reference.c_str()) != nullptr) {
    return {};
  }
  const fs::path texture(reference);
  if (texture.is_absolute()) return texture.lexically_normal().string();
  // Spellings of the reference to try: as written; with Windows separators turned
  // ("textures\\normal.png"); percent-decoded (glTF image URIs: "sphere%20normal.png"; not
  // every assimp decodes them).
  std::vector<fs::path> spellings{texture};
  if (reference.find('\\') != std::string::npos) {
    std::string slashed = reference;
    std::replace(slashed.begin(), slashed.end(), '\\', '/');
    spellings.emplace_back(slashed);
  }
  if (reference.find('%') != std::string::npos) {
    spellings.emplace_back(detail::uriDecodePath(reference));
  }
  std::error_code ec;
  for (const fs::path& directory : directories) {
    for (const fs::path& spelling : spellings) {
      if (fs::exists(directory / spelling, ec))
        return (directory / spelling).lexically_normal().string();
    }
  }
  return (directories.front() / texture).lexically_normal().string();
}

// The file bytes of an embedded texture ("*N" or a name assimp knows as embedded). Compressed
// textures (PNG, JPEG: what glTF embeds) are the file itself; uncompressed ones (mHeight > 0,
// BGRA texels, from some FBX) are not supported and give no bytes.
std::vector<unsigned char> embeddedTexture(const std::string& reference, const aiScene& scene) {
  if (reference.empty()) return {};
  const aiTexture* texture = scene.GetEmbeddedTexture(reference.c_str());
  if (texture == nullptr || texture->mHeight != 0 || texture->pcData == nullptr) return {};
  const auto* bytes = reinterpret_cast<const unsigned char*>(texture->pcData);
  return std::vector<unsigned char>(bytes, bytes + texture->mWidth);
}

// The file exists, is a regular, readable, non-empty file, and the scale is usable; else Error.
void checkMeshFile(const std::string& path, const MeshLoadOptions& options,
                   const std::string& what) {
  if (path.empty()) throw Error("mesh: no file name given");
  if (!std::isfinite(options.scale) || !(options.scale > 0.0)) {
    std::ostringstream message;
    message << what << ": scale = " << options.scale << " is out of range; valid: finite, > 0";
    throw Error(message.str());
  }
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error(what + " does not exist");
  if (fs::is_directory(path, ec)) throw Error(what + " is a directory, not a mesh file");
  if (!std::ifstream(path, std::ios::binary).good()) {
    throw Error(what + " cannot be opened (permissions?)");
  }
  if (fs::file_size(path, ec) == 0) throw Error(what + " is an empty file");
}

// assimp's scene of the file (owned by `importer`), triangulated, identical vertices joined;
// Error for a file it cannot read or one without meshes.
const aiScene& importScene(Assimp::Importer& importer, const std::string& path,
                           const std::string& what) {
  // Normals, colours and tangents are not used, and keeping them would stop
  // JoinIdenticalVertices from merging vertices that differ only there (STL stores one normal
  // per facet, so no vertex would ever be shared). Joining then depends on position and UVs.
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS,
                              aiComponent_NORMALS | aiComponent_TANGENTS_AND_BITANGENTS |
                                  aiComponent_COLORS | aiComponent_BONEWEIGHTS |
                                  aiComponent_ANIMATIONS | aiComponent_LIGHTS |
                                  aiComponent_CAMERAS);
  // The object frame is the file's own: Collada's <up_axis> would otherwise rotate Z-up files
  // to Y-up, which ROS tools (rviz, MoveIt) undo too. Its <unit> is still applied.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
  // A scene of bones only must not turn into a made-up skeleton mesh.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_NO_SKELETON_MESHES, true);
  // No normal generation: nothing reads normals. ValidateDataStructure runs first and rejects
  // garbage that parses into an inconsistent scene, which later steps would crash on.
  const unsigned flags = aiProcess_RemoveComponent | aiProcess_Triangulate |
                         aiProcess_JoinIdenticalVertices | aiProcess_SortByPType |
                         aiProcess_ValidateDataStructure;
  const aiScene* scene = nullptr;
  try {
    scene = importer.ReadFile(path, flags);
  } catch (const std::exception& e) {
    // assimp catches its own DeadlyImportError, but a stray std::exception must not escape
    // as anything but Error.
    throw Error(what + " cannot be read: " + oneLine(e.what()));
  }
  if (scene == nullptr) {
    throw Error(what + " cannot be read: " + oneLine(importer.GetErrorString()));
  }
  if (scene->mRootNode == nullptr || scene->mNumMeshes == 0 || scene->mMeshes == nullptr) {
    throw Error(what + " has no triangles");
  }
  return *scene;
}

// The scene's meshes flattened into one: every node's meshes with the node's accumulated
// transform, in metres, and the first normal texture a mesh's material names.
struct FlatMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> triangles;
  std::vector<Eigen::Vector2f> uvs;
  bool any_uvs = false;
  std::string texture_reference;
  std::vector<fs::path> texture_directories;  // where to look for it, first first
  // An .obj's material libraries as we read them (mtl_file.hpp), read once when needed.
  std::optional<std::vector<detail::ObjMaterial>> obj_materials;
};

// The normal texture `mesh`'s material names, when none was found yet.
void findNormalTexture(const aiScene& scene, const aiMesh& mesh, const std::string& path,
                       FlatMesh& flat) {
  if (!flat.texture_reference.empty() || mesh.mMaterialIndex >= scene.mNumMaterials ||
      scene.mMaterials == nullptr) {
    return;
  }
  const aiMaterial* material = scene.mMaterials[mesh.mMaterialIndex];
  flat.texture_reference = normalTextureOf(material);
  if (!isObjFile(path)) return;
  // The .mtl as we read it decides, so an .obj finds the same texture on every assimp: < 5.1
  // skips `norm`, and releases differ on quoted names, option arguments and keyword case.
  // assimp's reading stays for a material we cannot find by name.
  if (!flat.obj_materials) flat.obj_materials = detail::readObjMaterials(path);
  const detail::ObjMaterial* own =
      detail::findObjMaterial(*flat.obj_materials, materialName(material));
  if (own != nullptr && !own->material.normalTexture().empty()) {
    flat.texture_reference = own->material.normalTexture();
  }
  if (own != nullptr && !flat.texture_reference.empty()) {
    flat.texture_directories.insert(flat.texture_directories.begin(), own->mtl_directory);
  }
}

// Appends `mesh`'s triangles, and its vertices and UVs placed by `transform`.
void appendMesh(const aiMesh& mesh, const Eigen::Matrix4d& transform, const std::string& what,
                FlatMesh& flat) {
  const size_t offset = flat.vertices.size();
  if (offset + mesh.mNumVertices > static_cast<size_t>(std::numeric_limits<int>::max())) {
    throw Error(what + " has more vertices than supported");
  }
  size_t mesh_triangles = 0;
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
    const aiFace& face = mesh.mFaces[f];
    if (face.mNumIndices != 3) continue;
    Eigen::Vector3i triangle;
    for (int k = 0; k < 3; ++k) {
      if (face.mIndices[k] >= mesh.mNumVertices) {
        throw Error(what + " is corrupt: a face refers to a vertex that does not exist");
      }
      triangle[k] = static_cast<int>(offset + face.mIndices[k]);
    }
    flat.triangles.push_back(triangle);
    ++mesh_triangles;
  }
  if (mesh_triangles == 0) return;

  flat.vertices.reserve(offset + mesh.mNumVertices);
  const Eigen::Matrix3d linear = transform.topLeftCorner<3, 3>();
  const Eigen::Vector3d translation = transform.topRightCorner<3, 1>();
  for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
    const aiVector3D& p = mesh.mVertices[v];
    flat.vertices.push_back((linear * Eigen::Vector3d(p.x, p.y, p.z) + translation).cast<float>());
  }
  // UV policy: as soon as one mesh has UVs the merged mesh has them; meshes without get
  // (0, 0) so every vertex has one (see TexturedMesh).
  const bool has_uvs = mesh.HasTextureCoords(0);
  if (has_uvs && !flat.any_uvs) {
    flat.uvs.assign(offset, Eigen::Vector2f::Zero());
    flat.any_uvs = true;
  }
  if (flat.any_uvs) {
    flat.uvs.reserve(flat.vertices.size());
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      flat.uvs.push_back(
          has_uvs ? Eigen::Vector2f(mesh.mTextureCoords[0][v].x, mesh.mTextureCoords[0][v].y)
                  : Eigen::Vector2f::Zero());
    }
  }
}

// Flattens the node tree, iteratively so a deep hierarchy cannot exhaust the call stack.
FlatMesh flattenScene(const aiScene& scene, const std::string& path, double scale_factor,
                      const std::string& what) {
  FlatMesh flat;
  std::error_code ec;
  flat.texture_directories.push_back(fs::absolute(fs::path(path), ec).parent_path());
  const Eigen::Matrix4d scale =
      Eigen::Vector4d(scale_factor, scale_factor, scale_factor, 1.0).asDiagonal();
  std::vector<std::pair<const aiNode*, Eigen::Matrix4d>> pending{
      {scene.mRootNode, scale * toEigen(scene.mRootNode->mTransformation)}};
  std::unordered_set<const aiNode*> visited;
  while (!pending.empty()) {
    const auto [node, transform] = pending.back();
    pending.pop_back();
    if (!visited.insert(node).second) throw Error(what + " has a cyclic node hierarchy");
    for (unsigned c = node->mNumChildren; c-- > 0;) {
      const aiNode* child = node->mChildren[c];
      if (child != nullptr)
        pending.emplace_back(child, transform * toEigen(child->mTransformation));
    }
    for (unsigned m = 0; m < node->mNumMeshes; ++m) {
      if (node->mMeshes[m] >= scene.mNumMeshes) continue;
      const aiMesh* mesh = scene.mMeshes[node->mMeshes[m]];
      if (mesh == nullptr || mesh->mVertices == nullptr ||
          !(mesh->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) {
        continue;  // points and lines: nothing to press into the gel
      }
      const size_t triangles_before = flat.triangles.size();
      appendMesh(*mesh, transform, what, flat);
      if (flat.triangles.size() == triangles_before) continue;
      findNormalTexture(scene, *mesh, path, flat);
    }
  }
  if (flat.triangles.empty()) throw Error(what + " has no triangles");
  return flat;
}

}  // namespace

TexturedMesh TexturedMesh::load(const std::string& path, const MeshLoadOptions& options) {
  const std::string what = "mesh '" + path + "'";
  checkMeshFile(path, options, what);
  Assimp::Importer importer;
  const aiScene& scene = importScene(importer, path, what);
  FlatMesh flat = flattenScene(scene, path, options.scale, what);

  TexturedMesh result;
  try {
    result = TexturedMesh(std::move(flat.vertices), std::move(flat.triangles), std::move(flat.uvs));
  } catch (const Error& e) {
    // "mesh: vertex 3 has a non-finite coordinate" -> "mesh 'x.obj': vertex 3 ...".
    std::string detail = e.what();
    if (detail.rfind("mesh: ", 0) == 0) detail.erase(0, 6);
    throw Error(what + ": " + detail);
  }
  result.normal_texture_path_ =
      resolveTexture(flat.texture_reference, scene, flat.texture_directories);
  result.normal_texture_reference_ = flat.texture_reference;
  result.embedded_normal_texture_ = embeddedTexture(flat.texture_reference, scene);
  result.source_path_ = path;
  return result;
}

}  // namespace norm2tex
