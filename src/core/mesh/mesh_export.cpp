// saveMesh: TexturedMesh -> file through assimp's Exporter (and an OBJ material of our own),
// glTF through our own writer (gltf_writer.hpp: assimp's differs between releases).
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include <assimp/material.h>
#include <assimp/mesh.h>
#include <assimp/scene.h>
#include <assimp/Exporter.hpp>

#include "mesh/gltf_writer.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/mesh/uv_unwrap.hpp"

namespace norm2tex {
namespace {

namespace fs = std::filesystem;

constexpr const char* kMaterialName = "norm2tex_material";

std::string oneLine(std::string text) {
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text.empty() ? "unknown error" : text;
}

// One mesh, one material, one node. aiScene's destructor frees all of it.
std::unique_ptr<aiScene> makeScene(const TexturedMesh& mesh) {
  auto scene = std::make_unique<aiScene>();
  scene->mRootNode = new aiNode("norm2tex");
  scene->mRootNode->mNumMeshes = 1;
  scene->mRootNode->mMeshes = new unsigned[1]{0};

  scene->mNumMaterials = 1;
  scene->mMaterials = new aiMaterial* [1] { new aiMaterial() };
  const aiString material_name(kMaterialName);
  scene->mMaterials[0]->AddProperty(&material_name, AI_MATKEY_NAME);

  auto* out = new aiMesh();
  scene->mNumMeshes = 1;
  scene->mMeshes = new aiMesh* [1] { out };
  out->mName = aiString("norm2tex");
  out->mMaterialIndex = 0;
  out->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  const std::vector<Eigen::Vector3f>& vertices = mesh.vertices();
  out->mNumVertices = static_cast<unsigned>(vertices.size());
  out->mVertices = new aiVector3D[vertices.size()];
  for (size_t i = 0; i < vertices.size(); ++i) {
    out->mVertices[i] = aiVector3D(vertices[i].x(), vertices[i].y(), vertices[i].z());
  }
  if (mesh.hasUvs()) {
    out->mNumUVComponents[0] = 2;
    out->mTextureCoords[0] = new aiVector3D[vertices.size()];
    for (size_t i = 0; i < vertices.size(); ++i) {
      out->mTextureCoords[0][i] = aiVector3D(mesh.uvs()[i].x(), mesh.uvs()[i].y(), 0.0f);
    }
  }
  const std::vector<Eigen::Vector3i>& triangles = mesh.triangles();
  out->mNumFaces = static_cast<unsigned>(triangles.size());
  out->mFaces = new aiFace[triangles.size()];
  for (size_t i = 0; i < triangles.size(); ++i) {
    aiFace& face = out->mFaces[i];
    face.mNumIndices = 3;
    face.mIndices = new unsigned[3];
    for (int k = 0; k < 3; ++k) face.mIndices[k] = static_cast<unsigned>(triangles[i][k]);
  }
  return scene;
}

// The texture as the .obj's material should name it: relative to the .obj's directory when
// there is such a path, else absolute.
std::string textureReference(const std::string& texture, const fs::path& obj_directory) {
  std::error_code ec;
  const fs::path absolute = fs::absolute(texture, ec).lexically_normal();
  if (ec) return texture;
  const fs::path relative = absolute.lexically_relative(obj_directory);
  if (relative.empty()) return absolute.generic_string();
  return relative.generic_string();
}

}  // namespace

void saveMesh(const TexturedMesh& mesh, const std::string& path,
              const std::string& normal_texture) {
  const std::string what = "mesh '" + path + "'";
  if (path.empty()) throw Error("saveMesh: no file name given");
  if (mesh.triangles().empty()) throw Error("saveMesh: " + what + ": the mesh is empty");
  std::string extension = fs::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  // ASCII PLY keeps the file readable; binary STL is what every slicer expects.
  std::string format;
  if (extension == ".obj") {
    format = normal_texture.empty() ? "objnomtl" : "obj";
  } else if (extension == ".ply") {
    format = "ply";
  } else if (extension == ".stl") {
    format = "stlb";
  } else if (extension == ".dae") {
    format = "collada";
  } else if (extension == ".glb") {
    format = "glb2";
  } else if (extension == ".gltf") {
    format = "gltf2";
  } else {
    throw Error("saveMesh: " + what + " has an unknown extension '" + extension +
                "'; valid: .obj, .ply, .stl, .dae, .glb, .gltf");
  }

  std::error_code ec;
  const fs::path absolute = fs::absolute(path, ec).lexically_normal();
  const fs::path directory = absolute.parent_path();
  if (!fs::is_directory(directory, ec)) {
    throw Error("saveMesh: cannot write " + what + ": directory '" + directory.string() +
                "' does not exist");
  }
  if (fs::is_directory(absolute, ec)) {
    throw Error("saveMesh: cannot write " + what + ": it is a directory");
  }

  if (format == "glb2" || format == "gltf2") {
    const std::string reference =
        normal_texture.empty() ? std::string() : textureReference(normal_texture, directory);
    detail::writeGltf(mesh, path, format == "glb2", reference, kMaterialName);
    return;
  }
  const std::unique_ptr<aiScene> scene = makeScene(mesh);
  if (!normal_texture.empty() && format != "obj") {
    const aiString reference(textureReference(normal_texture, directory));
    scene->mMaterials[0]->AddProperty(&reference, AI_MATKEY_TEXTURE(aiTextureType_NORMALS, 0));
  }
  Assimp::Exporter exporter;
  aiReturn status = aiReturn_FAILURE;
  try {
    status = exporter.Export(scene.get(), format, path);
  } catch (const std::exception& e) {
    throw Error("saveMesh: cannot write " + what + ": " + oneLine(e.what()));
  }
  if (status != aiReturn_SUCCESS) {
    throw Error("saveMesh: cannot write " + what + ": " + oneLine(exporter.GetErrorString()));
  }
  // assimp reports success even when it could not open the file on some paths.
  if (!fs::is_regular_file(path, ec) || fs::file_size(path, ec) == 0) {
    throw Error("saveMesh: cannot write " + what + " (permissions?)");
  }

  if (format == "obj") {
    // assimp's material file is <stem>.mtl, named by "mtllib" in the .obj; ours replaces it so
    // the normal texture is referenced the way TexturedMesh::load and most tools read it.
    const fs::path mtl = fs::path(path).replace_extension(".mtl");
    const std::string reference = textureReference(normal_texture, directory);
    std::ofstream file(mtl, std::ios::binary | std::ios::trunc);
    file << "# norm2tex: material with the normal texture\n"
         << "newmtl " << kMaterialName << "\n"
         << "Ka 0 0 0\nKd 0.8 0.8 0.8\nKs 0 0 0\nd 1\nillum 1\n"
         << "map_Bump " << reference << "\n"
         << "norm " << reference << "\n";
    file.close();
    if (!file) throw Error("saveMesh: cannot write material file '" + mtl.string() + "'");
  }
}

}  // namespace norm2tex
