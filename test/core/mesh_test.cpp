#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "norm2tex/common/error.hpp"
#include "norm2tex/mesh/textured_mesh.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

using test::expectError;

namespace fs = std::filesystem;

void writeFile(const std::string& path, const std::string& content) {
  std::ofstream file(path, std::ios::binary);
  file << content;
  ASSERT_TRUE(file.good()) << path;
}

void expectBounds(const TexturedMesh& mesh, const Eigen::Vector3f& min, const Eigen::Vector3f& max,
                  float tolerance = 1e-6f) {
  ASSERT_FALSE(mesh.bounds().isEmpty());
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(mesh.bounds().min()[k], min[k], tolerance) << "axis " << k;
    EXPECT_NEAR(mesh.bounds().max()[k], max[k], tolerance) << "axis " << k;
  }
}

// The UV of the vertex at `position`, or NaN when there is none.
Eigen::Vector2f uvAt(const TexturedMesh& mesh, const Eigen::Vector3f& position) {
  for (size_t i = 0; i < mesh.vertices().size(); ++i) {
    if ((mesh.vertices()[i] - position).norm() < 1e-6f) return mesh.uvs().at(i);
  }
  ADD_FAILURE() << "no vertex at " << position.transpose();
  return Eigen::Vector2f::Constant(std::numeric_limits<float>::quiet_NaN());
}

std::string base64(const std::string& bytes) {
  static const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v =
        (uint8_t(bytes[i]) << 16) | (uint8_t(bytes[i + 1]) << 8) | uint8_t(bytes[i + 2]);
    for (int s = 18; s >= 0; s -= 6) out += alphabet[(v >> s) & 63];
  }
  if (i + 1 == bytes.size()) {
    const uint32_t v = uint8_t(bytes[i]) << 16;
    out += alphabet[(v >> 18) & 63];
    out += alphabet[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == bytes.size()) {
    const uint32_t v = (uint8_t(bytes[i]) << 16) | (uint8_t(bytes[i + 1]) << 8);
    out += alphabet[(v >> 18) & 63];
    out += alphabet[(v >> 12) & 63];
    out += alphabet[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

template <typename T>
void appendRaw(std::string& bytes, const T& value) {
  bytes.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

// A glTF 2.0 file: one node (translated by +2 in z) with a triangle carrying TEXCOORD_0 and a
// material with a normalTexture; with `second_primitive`, first a triangle without UVs.
std::string gltf(const std::string& image_uri, bool second_primitive) {
  std::string buffer;
  for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) appendRaw(buffer, v);  // 0..35
  for (float v : {0.25f, 0.f, 1.f, 0.f, 0.f, 1.f}) appendRaw(buffer, v);               // 36..59
  for (float v : {0.f, 0.f, 1.f, 1.f, 0.f, 1.f, 0.f, 1.f, 1.f}) appendRaw(buffer, v);  // 60..95
  // The primitive without UVs comes first, so UVs start part-way through the merged mesh.
  std::string primitives;
  if (second_primitive) primitives = R"({"attributes": {"POSITION": 2}, "mode": 4}, )";
  primitives += R"({"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": 0, "mode": 4})";
  return R"({
  "asset": {"version": "2.0"},
  "scene": 0,
  "scenes": [{"nodes": [0]}],
  "nodes": [{"mesh": 0, "translation": [0, 0, 2]}],
  "meshes": [{"primitives": [)" +
         primitives + R"(]}],
  "materials": [{"normalTexture": {"index": 0}}],
  "textures": [{"source": 0}],
  "images": [{"uri": ")" +
         image_uri + R"("}],
  "buffers": [{"byteLength": 96, "uri": "data:application/octet-stream;base64,)" +
         base64(buffer) + R"("}],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 36},
    {"buffer": 0, "byteOffset": 36, "byteLength": 24},
    {"buffer": 0, "byteOffset": 60, "byteLength": 36}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
     "min": [0, 0, 0], "max": [1, 1, 0]},
    {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"},
    {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC3",
     "min": [0, 0, 1], "max": [1, 1, 1]}]
})";
}

// ---------------------------------------------------------------------------------------------
// Loading each format.

TEST(TexturedMeshLoad, ObjWithUvsInMillimetresAndMapBump) {
  test::ScratchDirectory dir;
  writeFile(dir.path("square.mtl"), "newmtl skin\nKd 1 1 1\nmap_Bump normal.png\n");
  writeFile(dir.path("square.obj"),
            "mtllib square.mtl\n"
            "v 0 0 0\nv 10 0 0\nv 10 20 0\nv 0 20 5\n"
            "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
            "usemtl skin\n"
            "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n");
  MeshLoadOptions options;
  options.scale = 0.001;
  const TexturedMesh mesh = TexturedMesh::load(dir.path("square.obj"), options);
  EXPECT_EQ(mesh.triangles().size(), 2u);
  EXPECT_EQ(mesh.vertices().size(), 4u) << "shared corners must be joined";
  expectBounds(mesh, {0, 0, 0}, {0.010f, 0.020f, 0.005f});
  ASSERT_TRUE(mesh.hasUvs());
  ASSERT_EQ(mesh.uvs().size(), mesh.vertices().size());
  // OBJ UVs are OpenGL-style already: delivered as written.
  EXPECT_TRUE(uvAt(mesh, {0.010f, 0.020f, 0}).isApprox(Eigen::Vector2f(1, 1)));
  EXPECT_TRUE(uvAt(mesh, {0.010f, 0, 0}).isApprox(Eigen::Vector2f(1, 0)));
  EXPECT_TRUE(uvAt(mesh, {0, 0.020f, 0.005f}).isApprox(Eigen::Vector2f(0, 1)));
  const fs::path texture(mesh.normalTexturePath());
  EXPECT_TRUE(texture.is_absolute()) << texture;
  EXPECT_EQ(texture, fs::path(dir.path("normal.png")).lexically_normal());
  EXPECT_EQ(mesh.sourcePath(), dir.path("square.obj"));
}

TEST(TexturedMeshLoad, ObjNormKeywordAndRelativeSubdirectory) {
  test::ScratchDirectory dir;
  fs::create_directories(dir.path("models"));
  writeFile(dir.path("models/a.mtl"), "newmtl m\nnorm ../textures/n.png\n");
  writeFile(dir.path("models/a.obj"),
            "mtllib a.mtl\nusemtl m\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
            "f 1/1 2/2 3/3\n");
  // A relative mesh path must still give an absolute texture path.
  const fs::path cwd = fs::current_path();
  fs::current_path(dir.root());
  TexturedMesh mesh;
  try {
    mesh = TexturedMesh::load("models/a.obj");
  } catch (...) {
    fs::current_path(cwd);
    throw;
  }
  fs::current_path(cwd);
  EXPECT_EQ(mesh.triangles().size(), 1u);
  EXPECT_EQ(fs::path(mesh.normalTexturePath()),
            fs::path(dir.path("textures/n.png")).lexically_normal());
}

TEST(TexturedMeshLoad, ObjBumpOptionsAndWindowsSeparators) {
  test::ScratchDirectory dir;
  fs::create_directories(dir.path("tex"));
  writeFile(dir.path("tex/normal.png"), "not read by the loader");
  writeFile(dir.path("w.mtl"), "newmtl m\nmap_Bump -bm 0.3 tex\\normal.png\n");
  writeFile(dir.path("w.obj"), "mtllib w.mtl\nusemtl m\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const TexturedMesh mesh = TexturedMesh::load(dir.path("w.obj"));
  EXPECT_EQ(fs::path(mesh.normalTexturePath()),
            fs::path(dir.path("tex/normal.png")).lexically_normal());
}

TEST(TexturedMeshLoad, ObjWithoutMaterialHasNoNormalTexture) {
  test::ScratchDirectory dir;
  writeFile(dir.path("t.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const TexturedMesh mesh = TexturedMesh::load(dir.path("t.obj"));
  EXPECT_EQ(mesh.triangles().size(), 1u);
  EXPECT_FALSE(mesh.hasUvs());
  EXPECT_TRUE(mesh.normalTexturePath().empty());
}

TEST(TexturedMeshLoad, JoinIdenticalVerticesMergesCubeCorners) {
  test::ScratchDirectory dir;
  // 8 corners, 12 triangles: unjoined, assimp's OBJ reader gives 36 vertices.
  writeFile(dir.path("cube.obj"),
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
            "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\n"
            "f 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n");
  const TexturedMesh mesh = TexturedMesh::load(dir.path("cube.obj"));
  EXPECT_EQ(mesh.triangles().size(), 12u);
  EXPECT_EQ(mesh.vertices().size(), 8u);
  expectBounds(mesh, {0, 0, 0}, {1, 1, 1});
  // Every triangle still spans three distinct corners.
  for (const Eigen::Vector3i& t : mesh.triangles()) {
    EXPECT_TRUE(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
  }
}

TEST(TexturedMeshLoad, AsciiStlHasNoUvsAndJoinsFacetCorners) {
  test::ScratchDirectory dir;
  // A tetrahedron; facet normals differ, yet corners must be shared after loading.
  std::string stl = "solid tet\n";
  const float p[4][3] = {{0, 0, 0}, {30, 0, 0}, {0, 40, 0}, {0, 0, 50}};
  const int faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  for (const auto& f : faces) {
    const Eigen::Vector3f a(p[f[0]][0], p[f[0]][1], p[f[0]][2]),
        b(p[f[1]][0], p[f[1]][1], p[f[1]][2]), c(p[f[2]][0], p[f[2]][1], p[f[2]][2]);
    const Eigen::Vector3f n = (b - a).cross(c - a).normalized();
    stl += " facet normal " + std::to_string(n.x()) + " " + std::to_string(n.y()) + " " +
           std::to_string(n.z()) + "\n  outer loop\n";
    for (int k = 0; k < 3; ++k) {
      stl += "   vertex " + std::to_string(p[f[k]][0]) + " " + std::to_string(p[f[k]][1]) + " " +
             std::to_string(p[f[k]][2]) + "\n";
    }
    stl += "  endloop\n endfacet\n";
  }
  stl += "endsolid tet\n";
  writeFile(dir.path("tet.stl"), stl);
  MeshLoadOptions options;
  options.scale = 0.001;
  const TexturedMesh mesh = TexturedMesh::load(dir.path("tet.stl"), options);
  EXPECT_EQ(mesh.triangles().size(), 4u);
  EXPECT_EQ(mesh.vertices().size(), 4u);
  EXPECT_FALSE(mesh.hasUvs());
  EXPECT_TRUE(mesh.uvs().empty());
  EXPECT_TRUE(mesh.normalTexturePath().empty());
  expectBounds(mesh, {0, 0, 0}, {0.030f, 0.040f, 0.050f});
}

TEST(TexturedMeshLoad, AsciiPlyQuadIsTriangulatedWithUvs) {
  test::ScratchDirectory dir;
  writeFile(dir.path("quad.ply"),
            "ply\nformat ascii 1.0\n"
            "element vertex 5\n"
            "property float x\nproperty float y\nproperty float z\n"
            "property float s\nproperty float t\n"
            "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
            "0 0 0 0 0\n2 0 0 1 0\n2 3 0 1 1\n0 3 0 0 1\n1 1 4 0.5 0.5\n"
            "4 0 1 2 3\n3 0 1 4\n");
  const TexturedMesh mesh = TexturedMesh::load(dir.path("quad.ply"));
  EXPECT_EQ(mesh.triangles().size(), 3u);
  expectBounds(mesh, {0, 0, 0}, {2, 3, 4});
  ASSERT_TRUE(mesh.hasUvs());
  EXPECT_TRUE(uvAt(mesh, {2, 3, 0}).isApprox(Eigen::Vector2f(1, 1)));
  EXPECT_TRUE(uvAt(mesh, {1, 1, 4}).isApprox(Eigen::Vector2f(0.5f, 0.5f)));
}

TEST(TexturedMeshLoad, ColladaAppliesNodeTransformsToEveryInstance) {
  test::ScratchDirectory dir;
  writeFile(dir.path("two.dae"), R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="meter" meter="1"/><up_axis>Y_UP</up_axis></asset>
  <library_geometries>
    <geometry id="sq" name="sq">
      <mesh>
        <source id="sq-pos">
          <float_array id="sq-pos-array" count="12">0 0 0 1 0 0 1 1 0 0 1 0</float_array>
          <technique_common>
            <accessor source="#sq-pos-array" count="4" stride="3">
              <param name="X" type="float"/><param name="Y" type="float"/>
              <param name="Z" type="float"/>
            </accessor>
          </technique_common>
        </source>
        <vertices id="sq-vtx"><input semantic="POSITION" source="#sq-pos"/></vertices>
        <triangles count="2">
          <input semantic="VERTEX" source="#sq-vtx" offset="0"/>
          <p>0 1 2 0 2 3</p>
        </triangles>
      </mesh>
    </geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="scene" name="scene">
      <node id="a" name="a"><translate>0 0 5</translate><instance_geometry url="#sq"/></node>
      <node id="b" name="b"><translate>0 0 7</translate><scale>2 1 1</scale>
        <instance_geometry url="#sq"/></node>
    </visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
)");
  const TexturedMesh mesh = TexturedMesh::load(dir.path("two.dae"));
  EXPECT_EQ(mesh.triangles().size(), 4u);
  expectBounds(mesh, {0, 0, 5}, {2, 1, 7}, 1e-5f);
  EXPECT_FALSE(mesh.hasUvs());
}

TEST(TexturedMeshLoad, ColladaKeepsZUpCoordinatesAndAppliesUnit) {
  test::ScratchDirectory dir;
  // Authored Z-up in millimetres: assimp would rotate it to Y-up; ROS tools do not.
  writeFile(dir.path("zup.dae"), R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="millimeter" meter="0.001"/><up_axis>Z_UP</up_axis></asset>
  <library_geometries><geometry id="t"><mesh>
    <source id="p"><float_array id="pa" count="9">0 0 0 10 0 0 0 20 30</float_array>
      <technique_common><accessor source="#pa" count="3" stride="3">
        <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
      </accessor></technique_common></source>
    <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
    <triangles count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 2</p></triangles>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="s">
    <node id="a"><instance_geometry url="#t"/></node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
)");
  const TexturedMesh mesh = TexturedMesh::load(dir.path("zup.dae"));
  EXPECT_EQ(mesh.triangles().size(), 1u);
  expectBounds(mesh, {0, 0, 0}, {0.010f, 0.020f, 0.030f});
}

TEST(TexturedMeshLoad, GltfNormalTextureNodeTransformAndUvConvention) {
  test::ScratchDirectory dir;
  writeFile(dir.path("tri.gltf"), gltf("tex/normal.png", false));
  const TexturedMesh mesh = TexturedMesh::load(dir.path("tri.gltf"));
  EXPECT_EQ(mesh.triangles().size(), 1u);
  expectBounds(mesh, {0, 0, 2}, {1, 1, 2});
  ASSERT_TRUE(mesh.hasUvs());
  // glTF's v runs down the image; assimp delivers OpenGL-style v = 1 - v (height_atlas.hpp).
  EXPECT_TRUE(uvAt(mesh, {0, 0, 2}).isApprox(Eigen::Vector2f(0.25f, 1.0f)));
  EXPECT_TRUE(uvAt(mesh, {0, 1, 2}).isApprox(Eigen::Vector2f(0.0f, 0.0f)));
  const fs::path texture(mesh.normalTexturePath());
  EXPECT_TRUE(texture.is_absolute()) << texture;
  EXPECT_EQ(texture, fs::path(dir.path("tex/normal.png")).lexically_normal());
}

TEST(TexturedMeshLoad, GltfEmbeddedNormalTextureGivesNoPath) {
  test::ScratchDirectory dir;
  writeFile(dir.path("embedded.gltf"),
            gltf("data:image/png;base64," + base64("\x89PNG\r\n\x1a\n not really"), false));
  const TexturedMesh mesh = TexturedMesh::load(dir.path("embedded.gltf"));
  EXPECT_EQ(mesh.triangles().size(), 1u);
  EXPECT_TRUE(mesh.normalTexturePath().empty()) << mesh.normalTexturePath();
}

TEST(TexturedMeshLoad, MixedUvsKeepUvsAndZeroTheMissingOnes) {
  test::ScratchDirectory dir;
  writeFile(dir.path("mixed.gltf"), gltf("normal.png", true));
  const TexturedMesh mesh = TexturedMesh::load(dir.path("mixed.gltf"));
  EXPECT_EQ(mesh.triangles().size(), 2u);
  expectBounds(mesh, {0, 0, 2}, {1, 1, 3});
  ASSERT_TRUE(mesh.hasUvs());
  ASSERT_EQ(mesh.uvs().size(), mesh.vertices().size());
  EXPECT_TRUE(uvAt(mesh, {1, 0, 2}).isApprox(Eigen::Vector2f(1.0f, 1.0f)));
  // The primitive without TEXCOORD_0: (0, 0).
  EXPECT_TRUE(uvAt(mesh, {0, 0, 3}).isZero());
  EXPECT_TRUE(uvAt(mesh, {1, 0, 3}).isZero());
  EXPECT_TRUE(uvAt(mesh, {0, 1, 3}).isZero());
  EXPECT_FALSE(mesh.normalTexturePath().empty());
}

// ---------------------------------------------------------------------------------------------
// Errors.

TEST(TexturedMeshErrors, ArrayConstructorRejectsBadInput) {
  const std::vector<Eigen::Vector3f> v{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<Eigen::Vector3i> t{{0, 1, 2}};
  EXPECT_NO_THROW(TexturedMesh(v, t));
  expectError([&] { TexturedMesh(v, {}); }, {"no triangles"});
  expectError([&] { TexturedMesh(v, {{0, 1, 3}}); }, {"triangle 0", "3"});
  expectError([&] { TexturedMesh(v, {{0, 1, 2}, {-1, 1, 2}}); }, {"triangle 1", "-1"});
  auto nan_vertices = v;
  nan_vertices[1].y() = std::numeric_limits<float>::quiet_NaN();
  expectError([&] { TexturedMesh(nan_vertices, t); }, {"vertex 1", "finite"});
  auto inf_vertices = v;
  inf_vertices[2].z() = std::numeric_limits<float>::infinity();
  expectError([&] { TexturedMesh(inf_vertices, t); }, {"vertex 2", "finite"});
  expectError([&] { TexturedMesh(v, t, {{0, 0}, {1, 0}}); }, {"2 UVs", "3 vertices"});
  expectError(
      [&] {
        TexturedMesh(v, t, {{0, 0}, {1, std::numeric_limits<float>::quiet_NaN()}, {0, 1}});
      },
      {"UV 1", "finite"});
}

TEST(TexturedMeshErrors, LoaderErrorsNameTheFile) {
  test::ScratchDirectory dir;
  const std::string missing = dir.path("missing.obj");
  expectError([&] { TexturedMesh::load(missing); }, {missing, "does not exist"});
  expectError([&] { TexturedMesh::load(dir.root()); }, {dir.root(), "directory"});
  expectError([&] { TexturedMesh::load(""); }, {"no file name"});

  const std::string empty = dir.path("empty.stl");
  writeFile(empty, "");
  expectError([&] { TexturedMesh::load(empty); }, {empty, "empty"});

  std::mt19937 random(7);
  std::string garbage(4096, '\0');
  for (char& c : garbage) c = static_cast<char>(random() & 0xff);
  for (const std::string name : {"garbage.ply", "garbage.bin", "garbage.dae", "garbage.gltf"}) {
    writeFile(dir.path(name), garbage);
    expectError([&] { TexturedMesh::load(dir.path(name)); }, {dir.path(name)});
  }
  // Truncated binary PLY: the header promises more than the file holds.
  writeFile(dir.path("truncated.ply"),
            "ply\nformat binary_little_endian 1.0\nelement vertex 1000\nproperty float x\n"
            "property float y\nproperty float z\nelement face 1000\n"
            "property list uchar int vertex_indices\nend_header\n\x01\x02\x03");
  expectError([&] { TexturedMesh::load(dir.path("truncated.ply")); }, {dir.path("truncated.ply")});

  const std::string lines = dir.path("lines.obj");
  writeFile(lines, "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\np 1\n");
  expectError([&] { TexturedMesh::load(lines); }, {lines, "no triangles"});

  const std::string good = dir.path("good.obj");
  writeFile(good, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  for (double scale : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN(),
                       std::numeric_limits<double>::infinity()}) {
    MeshLoadOptions options;
    options.scale = scale;
    expectError([&] { TexturedMesh::load(good, options); }, {good, "scale"});
  }
}

TEST(TexturedMeshErrors, BadFileContentNamesTheFile) {
  test::ScratchDirectory dir;
  // 1e39 overflows float; "nan" parses as NaN.
  for (const std::string x : {"1e39", "nan"}) {
    const std::string path = dir.path("bad_" + x + ".obj");
    writeFile(path, "v 0 0 0\nv " + x + " 0 0\nv 0 1 0\nf 1 2 3\n");
    expectError([&] { TexturedMesh::load(path); }, {path, "vertex 1", "finite"});
  }
  const std::string ply_header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n";
  const std::string bad_index = dir.path("bad_index.ply");
  writeFile(bad_index, ply_header + "3 0 1 7\n");
  expectError([&] { TexturedMesh::load(bad_index); }, {bad_index});
  const std::string good = dir.path("good.ply");
  writeFile(good, ply_header + "3 0 1 2\n");
  EXPECT_EQ(TexturedMesh::load(good).triangles().size(), 1u);
}

// ---------------------------------------------------------------------------------------------
// BVH.

// A wavy nx x ny grid (2 nx ny triangles) over [0, 0.1] x [0, 0.1] with jitter, triangles in
// random order so the BVH cannot lean on the generation order.
struct MeshArrays {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> triangles;
  std::vector<Eigen::Vector2f> uvs;
};

MeshArrays wavyGridArrays(int nx, int ny, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> jitter(-0.2f, 0.2f);
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector2f> uvs;
  const float step = 0.1f / nx;
  for (int y = 0; y <= ny; ++y) {
    for (int x = 0; x <= nx; ++x) {
      const float px = (x + jitter(random)) * step, py = (y + jitter(random)) * step;
      vertices.emplace_back(px, py, 0.01f * std::sin(60 * px) * std::cos(45 * py));
      uvs.emplace_back(float(x) / nx, float(y) / ny);
    }
  }
  std::vector<Eigen::Vector3i> triangles;
  for (int y = 0; y < ny; ++y) {
    for (int x = 0; x < nx; ++x) {
      const int a = y * (nx + 1) + x, b = a + 1, c = a + nx + 1, d = c + 1;
      triangles.emplace_back(a, b, d);
      triangles.emplace_back(a, d, c);
    }
  }
  std::shuffle(triangles.begin(), triangles.end(), random);
  return {std::move(vertices), std::move(triangles), std::move(uvs)};
}

TexturedMesh wavyGrid(int nx, int ny, unsigned seed) {
  MeshArrays a = wavyGridArrays(nx, ny, seed);
  return TexturedMesh(std::move(a.vertices), std::move(a.triangles), std::move(a.uvs));
}

Eigen::Isometry3f randomPose(std::mt19937& random) {
  std::normal_distribution<float> gauss;
  Eigen::Quaternionf q(gauss(random), gauss(random), gauss(random), gauss(random));
  q.normalize();
  Eigen::Isometry3f pose = Eigen::Isometry3f::Identity();
  pose.linear() = q.toRotationMatrix();
  pose.translation() = 0.05f * Eigen::Vector3f(gauss(random), gauss(random), gauss(random));
  return pose;
}

std::vector<int> bruteForce(const TexturedMesh& mesh, const Eigen::Isometry3f& pose,
                            const Eigen::AlignedBox3f& region) {
  std::vector<int> result;
  for (size_t i = 0; i < mesh.triangles().size(); ++i) {
    Eigen::AlignedBox3f box;
    for (int k = 0; k < 3; ++k) box.extend(pose * mesh.vertices()[mesh.triangles()[i][k]]);
    if (box.intersects(region)) result.push_back(static_cast<int>(i));
  }
  return result;
}

TEST(TexturedMeshBvh, QueryIsASupersetOfBruteForceAndSelective) {
  const TexturedMesh mesh = wavyGrid(300, 300, 1);
  const size_t n = mesh.triangles().size();
  ASSERT_EQ(n, 180000u);
  std::mt19937 random(42);
  std::uniform_int_distribution<size_t> pick_vertex(0, mesh.vertices().size() - 1);
  std::uniform_real_distribution<float> half_size(0.0005f, 0.004f);
  int small_queries = 0;
  for (int trial = 0; trial < 12; ++trial) {
    const Eigen::Isometry3f pose = randomPose(random);
    // Regions around a mapped vertex, so they touch the mesh; the last few are flat slabs.
    const Eigen::Vector3f centre = pose * mesh.vertices()[pick_vertex(random)];
    Eigen::Vector3f half = Eigen::Vector3f::Constant(half_size(random));
    if (trial >= 9) half.z() = 0.0f;  // zero-thickness region: closed intersection matters
    const Eigen::AlignedBox3f region(centre - half, centre + half);

    std::vector<int> found{-7};  // queryTriangles appends
    mesh.queryTriangles(pose, region, found);
    ASSERT_EQ(found.front(), -7);
    found.erase(found.begin());
    const std::set<int> found_set(found.begin(), found.end());
    EXPECT_EQ(found_set.size(), found.size()) << "duplicates";

    const std::vector<int> truth = bruteForce(mesh, pose, region);
    ASSERT_FALSE(truth.empty());
    for (int t : truth) {
      ASSERT_TRUE(found_set.count(t)) << "trial " << trial << " missed triangle " << t;
    }
    // Per-triangle bounds at the leaves keep the answer tight, not just conservative.
    EXPECT_LE(found.size(), truth.size() + truth.size() / 20 + 8) << "trial " << trial;
    EXPECT_LT(found.size(), n / 10) << "trial " << trial;
    if (found.size() < n / 100) ++small_queries;
  }
  EXPECT_GT(small_queries, 6);
}

TEST(TexturedMeshBvh, WholeEmptyAndTouchingRegions) {
  const TexturedMesh mesh = wavyGrid(40, 30, 3);
  const Eigen::Isometry3f identity = Eigen::Isometry3f::Identity();
  std::vector<int> all;
  mesh.queryTriangles(identity, mesh.bounds(), all);
  EXPECT_EQ(all.size(), mesh.triangles().size());
  std::sort(all.begin(), all.end());
  EXPECT_EQ(std::unique(all.begin(), all.end()), all.end());

  std::vector<int> none;
  mesh.queryTriangles(identity, Eigen::AlignedBox3f(), none);  // empty box
  EXPECT_TRUE(none.empty());
  const Eigen::Vector3f far(1, 1, 1);
  mesh.queryTriangles(identity, Eigen::AlignedBox3f(far, far + Eigen::Vector3f::Ones()), none);
  EXPECT_TRUE(none.empty());

  // A region whose floor is exactly the mesh's highest point touches it (closed test).
  const float top = mesh.bounds().max().z();
  std::vector<int> touching;
  mesh.queryTriangles(identity,
                      Eigen::AlignedBox3f(Eigen::Vector3f(-1, -1, top), Eigen::Vector3f(1, 1, 2)),
                      touching);
  EXPECT_FALSE(touching.empty());
  for (int t :
       bruteForce(mesh, identity,
                  Eigen::AlignedBox3f(Eigen::Vector3f(-1, -1, top), Eigen::Vector3f(1, 1, 2)))) {
    EXPECT_NE(std::find(touching.begin(), touching.end(), t), touching.end());
  }

  // A default-constructed mesh answers nothing and does not crash.
  const TexturedMesh empty_mesh;
  empty_mesh.queryTriangles(identity, mesh.bounds(), none);
  EXPECT_TRUE(none.empty());
}

TEST(TexturedMeshBvh, DegenerateMeshesStillBuild) {
  // Every triangle at the same place: the builder must halve rather than loop forever.
  std::vector<Eigen::Vector3f> vertices{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  std::vector<Eigen::Vector3i> triangles(1000, Eigen::Vector3i(0, 1, 2));
  const TexturedMesh same(vertices, triangles);
  std::vector<int> found;
  same.queryTriangles(Eigen::Isometry3f::Identity(), same.bounds(), found);
  EXPECT_EQ(found.size(), 1000u);

  // Collinear, zero-area triangles along x.
  std::vector<Eigen::Vector3f> line;
  std::vector<Eigen::Vector3i> slivers;
  for (int i = 0; i < 500; ++i) {
    line.emplace_back(float(i), 0, 0);
    line.emplace_back(float(i) + 0.5f, 0, 0);
    line.emplace_back(float(i) + 1.0f, 0, 0);
    slivers.emplace_back(3 * i, 3 * i + 1, 3 * i + 2);
  }
  const TexturedMesh flat(line, slivers);
  found.clear();
  flat.queryTriangles(
      Eigen::Isometry3f::Identity(),
      Eigen::AlignedBox3f(Eigen::Vector3f(9.5f, 0, 0), Eigen::Vector3f(10.2f, 0, 0)), found);
  std::sort(found.begin(), found.end());
  EXPECT_EQ(found, std::vector<int>({9, 10}));
}

// ---------------------------------------------------------------------------------------------
// Large meshes: build, query and load 200k triangles (timings printed, not asserted).

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void writeBinaryStl(const std::string& path, const TexturedMesh& mesh) {
  std::string bytes(80, ' ');
  appendRaw(bytes, static_cast<uint32_t>(mesh.triangles().size()));
  for (const Eigen::Vector3i& t : mesh.triangles()) {
    // Real facet normals: they differ between neighbours, and loading must still join corners.
    const Eigen::Vector3f& a = mesh.vertices()[t[0]];
    const Eigen::Vector3f n =
        (mesh.vertices()[t[1]] - a).cross(mesh.vertices()[t[2]] - a).normalized();
    for (int k = 0; k < 3; ++k) appendRaw(bytes, n[k]);
    for (int k = 0; k < 3; ++k) {
      for (int c = 0; c < 3; ++c) appendRaw(bytes, mesh.vertices()[t[k]][c] * 1000.0f);  // mm
    }
    appendRaw(bytes, static_cast<uint16_t>(0));
  }
  writeFile(path, bytes);
}

void writeBinaryPly(const std::string& path, const TexturedMesh& mesh) {
  std::string bytes = "ply\nformat binary_little_endian 1.0\nelement vertex " +
                      std::to_string(mesh.vertices().size()) +
                      "\nproperty float x\nproperty float y\nproperty float z\n"
                      "property float u\nproperty float v\nelement face " +
                      std::to_string(mesh.triangles().size()) +
                      "\nproperty list uchar int vertex_indices\nend_header\n";
  for (size_t i = 0; i < mesh.vertices().size(); ++i) {
    for (int c = 0; c < 3; ++c) appendRaw(bytes, mesh.vertices()[i][c]);
    for (int c = 0; c < 2; ++c) appendRaw(bytes, mesh.uvs()[i][c]);
  }
  for (const Eigen::Vector3i& t : mesh.triangles()) {
    appendRaw(bytes, static_cast<uint8_t>(3));
    for (int k = 0; k < 3; ++k) appendRaw(bytes, static_cast<int32_t>(t[k]));
  }
  writeFile(path, bytes);
}

TEST(TexturedMeshLarge, TwoHundredThousandTriangles) {
  MeshArrays arrays = wavyGridArrays(317, 317, 5);  // 200978 triangles
  auto start = std::chrono::steady_clock::now();
  const TexturedMesh mesh(std::move(arrays.vertices), std::move(arrays.triangles),
                          std::move(arrays.uvs));
  const double build = secondsSince(start);
  ASSERT_EQ(mesh.triangles().size(), 2u * 317 * 317);

  std::mt19937 random(9);
  std::vector<int> found;
  start = std::chrono::steady_clock::now();
  const int queries = 200;
  size_t returned = 0;
  for (int q = 0; q < queries; ++q) {
    const Eigen::Isometry3f pose = randomPose(random);
    const Eigen::Vector3f centre = pose * mesh.vertices()[random() % mesh.vertices().size()];
    // About a DIGIT gel: 19 x 15 mm, 3 mm deep.
    const Eigen::Vector3f half(0.0095f, 0.0075f, 0.0015f);
    found.clear();
    mesh.queryTriangles(pose, Eigen::AlignedBox3f(centre - half, centre + half), found);
    EXPECT_FALSE(found.empty());
    returned += found.size();
  }
  const double query = secondsSince(start) / queries;

  test::ScratchDirectory dir;
  writeBinaryStl(dir.path("big.stl"), mesh);
  writeBinaryPly(dir.path("big.ply"), mesh);
  MeshLoadOptions mm;
  mm.scale = 0.001;
  start = std::chrono::steady_clock::now();
  const TexturedMesh stl = TexturedMesh::load(dir.path("big.stl"), mm);
  const double load_stl = secondsSince(start);
  start = std::chrono::steady_clock::now();
  const TexturedMesh ply = TexturedMesh::load(dir.path("big.ply"));
  const double load_ply = secondsSince(start);

  EXPECT_EQ(stl.triangles().size(), mesh.triangles().size());
  EXPECT_EQ(stl.vertices().size(), mesh.vertices().size()) << "STL corners must be joined";
  EXPECT_FALSE(stl.hasUvs());
  EXPECT_TRUE(stl.bounds().isApprox(mesh.bounds(), 1e-4f));
  EXPECT_EQ(ply.triangles().size(), mesh.triangles().size());
  EXPECT_EQ(ply.vertices().size(), mesh.vertices().size());
  EXPECT_TRUE(ply.hasUvs());
  EXPECT_TRUE(ply.bounds().isApprox(mesh.bounds()));

  std::cout << "[ timing   ] 200978 triangles: BVH build " << build * 1e3 << " ms (with "
            << "validation), query " << query * 1e6 << " us (" << returned / queries
            << " triangles returned on average), load binary STL " << load_stl * 1e3
            << " ms, binary PLY " << load_ply * 1e3 << " ms" << std::endl;
}

}  // namespace
}  // namespace norm2tex
