// saveMesh's glTF output read back without assimp: the GLB container and the JSON (read with
// yaml-cpp, a reader independent of the writer) are checked against the glTF 2.0 specification,
// and the buffer's positions, UVs and indices against the saved mesh.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "mesh/gltf_writer.hpp"
#include "norm2tex/mesh/mesh_primitives.hpp"
#include "norm2tex/mesh/textured_mesh.hpp"
#include "norm2tex/mesh/uv_unwrap.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

namespace fs = std::filesystem;

std::vector<unsigned char> readBytes(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

std::uint32_t u32(const std::vector<unsigned char>& bytes, size_t offset) {
  std::uint32_t value = 0;
  for (int k = 3; k >= 0; --k) value = (value << 8) | bytes.at(offset + k);  // little-endian
  return value;
}

// A glTF asset as a reader sees it: the JSON and the bytes of buffer 0.
struct Gltf {
  YAML::Node json;
  std::vector<unsigned char> buffer;
};

// Reads a .glb, checking its container: header, two 4-aligned chunks (JSON, BIN).
Gltf readGlb(const std::string& path) {
  const std::vector<unsigned char> bytes = readBytes(path);
  Gltf gltf;
  EXPECT_GE(bytes.size(), 28u);
  if (bytes.size() < 28) return gltf;
  EXPECT_EQ(u32(bytes, 0), 0x46546C67u) << "magic 'glTF'";
  EXPECT_EQ(u32(bytes, 4), 2u) << "container version";
  EXPECT_EQ(u32(bytes, 8), bytes.size()) << "total length";
  const std::uint32_t json_length = u32(bytes, 12);
  EXPECT_EQ(u32(bytes, 16), 0x4E4F534Au) << "first chunk is JSON";
  EXPECT_EQ(json_length % 4, 0u);
  const size_t bin_header = 20 + json_length;
  EXPECT_LE(bin_header + 8, bytes.size());
  if (bin_header + 8 > bytes.size()) return gltf;
  const std::uint32_t bin_length = u32(bytes, bin_header);
  EXPECT_EQ(u32(bytes, bin_header + 4), 0x004E4942u) << "second chunk is BIN";
  EXPECT_EQ(bin_length % 4, 0u);
  EXPECT_EQ(bin_header + 8 + bin_length, bytes.size());
  gltf.json = YAML::Load(std::string(bytes.begin() + 20, bytes.begin() + 20 + json_length));
  gltf.buffer.assign(bytes.begin() + bin_header + 8, bytes.end());
  return gltf;
}

// Reads a .gltf and its buffer: the file its URI names, or a base64 data URI.
Gltf readGltfJson(const std::string& path) {
  const std::vector<unsigned char> bytes = readBytes(path);
  Gltf gltf;
  gltf.json = YAML::Load(std::string(bytes.begin(), bytes.end()));
  const std::string uri = gltf.json["buffers"][0]["uri"].as<std::string>();
  const std::string data = "data:application/octet-stream;base64,";
  if (uri.rfind(data, 0) != 0) {
    gltf.buffer = readBytes((fs::path(path).parent_path() / uri).string());
    return gltf;
  }
  const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::uint32_t bits = 0;
  int count = 0;
  for (size_t i = data.size(); i < uri.size() && uri[i] != '='; ++i) {
    const size_t value = alphabet.find(uri[i]);
    EXPECT_NE(value, std::string::npos) << "base64 character '" << uri[i] << "'";
    bits = (bits << 6) | static_cast<std::uint32_t>(value & 63);
    if ((count += 6) >= 8) {
      count -= 8;
      gltf.buffer.push_back(static_cast<unsigned char>((bits >> count) & 0xFF));
    }
  }
  return gltf;
}

// The floats (or unsigned ints) of an accessor, checked against its buffer view and buffer.
template <typename T>
std::vector<T> accessor(const Gltf& gltf, int index, int component_type, const std::string& type,
                        int components) {
  const YAML::Node a = gltf.json["accessors"][index];
  EXPECT_EQ(a["componentType"].as<int>(), component_type) << "accessor " << index;
  EXPECT_EQ(a["type"].as<std::string>(), type) << "accessor " << index;
  const YAML::Node view = gltf.json["bufferViews"][a["bufferView"].as<int>()];
  EXPECT_EQ(view["buffer"].as<int>(), 0);
  const size_t count = a["count"].as<size_t>();
  const size_t offset = view["byteOffset"].as<size_t>() + a["byteOffset"].as<size_t>(0);
  EXPECT_EQ(offset % 4, 0u) << "accessor " << index << " is 4-aligned";
  EXPECT_FALSE(view["byteStride"]) << "tightly packed";
  EXPECT_GE(view["byteLength"].as<size_t>(), count * components * sizeof(T));
  EXPECT_LE(view["byteOffset"].as<size_t>() + view["byteLength"].as<size_t>(),
            gltf.json["buffers"][0]["byteLength"].as<size_t>());
  EXPECT_LE(gltf.json["buffers"][0]["byteLength"].as<size_t>(), gltf.buffer.size());
  std::vector<T> values(count * components);
  if (offset + values.size() * sizeof(T) > gltf.buffer.size()) {
    ADD_FAILURE() << "accessor " << index << " runs past the buffer";
    return {};
  }
  std::memcpy(values.data(), gltf.buffer.data() + offset, values.size() * sizeof(T));
  return values;
}

// Checks the file's mesh against `mesh`: positions within 1e-6 and min/max exact, unit normals
// pointing away from the centre (a sphere), UVs in glTF's convention (v_file = 1 - v), the same
// indices, and the material's normal texture URI.
void expectMeshInFile(const Gltf& gltf, const TexturedMesh& mesh, const std::string& texture_uri) {
  ASSERT_TRUE(gltf.json.IsMap());
  EXPECT_EQ(gltf.json["asset"]["version"].as<std::string>(), "2.0");
  const YAML::Node primitive = gltf.json["meshes"][0]["primitives"][0];
  EXPECT_EQ(primitive["mode"].as<int>(4), 4);  // triangles
  const YAML::Node attributes = primitive["attributes"];
  const size_t n = mesh.vertices().size();

  const std::vector<float> positions =
      accessor<float>(gltf, attributes["POSITION"].as<int>(), 5126, "VEC3", 3);
  ASSERT_EQ(positions.size(), 3 * n);
  Eigen::Vector3f low = Eigen::Vector3f::Constant(1e30f), high = -low;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3f p(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
    EXPECT_LE((p - mesh.vertices()[i]).norm(), 1e-6f) << "vertex " << i;
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  const YAML::Node position_accessor = gltf.json["accessors"][attributes["POSITION"].as<int>()];
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(position_accessor["min"][k].as<float>(), low[k]) << "POSITION min, axis " << k;
    EXPECT_EQ(position_accessor["max"][k].as<float>(), high[k]) << "POSITION max, axis " << k;
  }

  const std::vector<float> normals =
      accessor<float>(gltf, attributes["NORMAL"].as<int>(), 5126, "VEC3", 3);
  ASSERT_EQ(normals.size(), 3 * n);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3f normal(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]);
    EXPECT_NEAR(normal.norm(), 1.0f, 1e-5f) << "vertex " << i;
    EXPECT_GT(normal.dot(mesh.vertices()[i].normalized()), 0.9f) << "vertex " << i;
  }

  if (mesh.hasUvs()) {
    const std::vector<float> uvs =
        accessor<float>(gltf, attributes["TEXCOORD_0"].as<int>(), 5126, "VEC2", 2);
    ASSERT_EQ(uvs.size(), 2 * n);
    for (size_t i = 0; i < n; ++i) {
      EXPECT_NEAR(uvs[2 * i], mesh.uvs()[i].x(), 1e-6f) << "vertex " << i;
      EXPECT_NEAR(uvs[2 * i + 1], 1.0f - mesh.uvs()[i].y(), 1e-6f) << "vertex " << i;
    }
  } else {
    EXPECT_FALSE(attributes["TEXCOORD_0"]);
  }

  const std::vector<std::uint32_t> indices =
      accessor<std::uint32_t>(gltf, primitive["indices"].as<int>(), 5125, "SCALAR", 1);
  ASSERT_EQ(indices.size(), 3 * mesh.triangles().size());
  for (size_t t = 0; t < mesh.triangles().size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(indices[3 * t + k], static_cast<std::uint32_t>(mesh.triangles()[t][k]));
    }
  }

  const YAML::Node material = gltf.json["materials"][primitive["material"].as<int>()];
  if (texture_uri.empty()) {
    EXPECT_FALSE(material["normalTexture"]);
    return;
  }
  const int texture = material["normalTexture"]["index"].as<int>();
  const int image = gltf.json["textures"][texture]["source"].as<int>();
  EXPECT_EQ(gltf.json["images"][image]["uri"].as<std::string>(), texture_uri);
}

class GltfExport : public testing::Test {
 protected:
  void SetUp() override {
    const TexturedMesh sphere = makeUvSphere(0.005, 12, 24);
    mesh_ =
        unwrapUvs(TexturedMesh(sphere.vertices(), sphere.triangles()), UnwrapOptions{256, 2}).mesh;
    fs::create_directories(scratch_.path("textures"));
    texture_ = scratch_.path("textures/sphere normal.png");
    std::ofstream(texture_) << "not read";
  }
  test::ScratchDirectory scratch_;
  TexturedMesh mesh_;
  std::string texture_;
};

TEST_F(GltfExport, GlbIsValidAndHoldsTheMesh) {
  const std::string path = scratch_.path("sphere.glb");
  saveMesh(mesh_, path, texture_);
  expectMeshInFile(readGlb(path), mesh_, "textures/sphere%20normal.png");
  // And assimp reads it back as it was saved, texture included.
  const TexturedMesh loaded = TexturedMesh::load(path);
  ASSERT_EQ(loaded.triangles().size(), mesh_.triangles().size());
  EXPECT_EQ(loaded.normalTexturePath(), fs::absolute(texture_).lexically_normal().string());
}

TEST_F(GltfExport, GltfWithItsBufferBesideItOrEmbedded) {
  // <stem>.bin beside the .gltf.
  const std::string path = scratch_.path("sphere.gltf");
  saveMesh(mesh_, path, texture_);
  const Gltf gltf = readGltfJson(path);
  EXPECT_EQ(gltf.json["buffers"][0]["uri"].as<std::string>(), "sphere.bin");
  EXPECT_EQ(gltf.json["buffers"][0]["byteLength"].as<size_t>(), gltf.buffer.size());
  expectMeshInFile(gltf, mesh_, "textures/sphere%20normal.png");
  EXPECT_EQ(TexturedMesh::load(path).normalTexturePath(),
            fs::absolute(texture_).lexically_normal().string());
  // A name a URI must escape: the buffer is embedded, and assimp reads it all the same.
  const std::string spaced = scratch_.path("my sphere.gltf");
  saveMesh(mesh_, spaced, texture_);
  EXPECT_FALSE(fs::exists(scratch_.path("my sphere.bin")));
  const Gltf embedded = readGltfJson(spaced);
  EXPECT_EQ(embedded.json["buffers"][0]["byteLength"].as<size_t>(), embedded.buffer.size());
  expectMeshInFile(embedded, mesh_, "textures/sphere%20normal.png");
  EXPECT_EQ(TexturedMesh::load(spaced).triangles().size(), mesh_.triangles().size());
}

// The UV convention on a triangle whose UVs are known: glTF's origin is the image's top left.
TEST_F(GltfExport, UvOriginIsTheImagesTopLeft) {
  const TexturedMesh triangle(
      {Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(1, 0, 0), Eigen::Vector3f(0, 1, 0)},
      {Eigen::Vector3i(0, 1, 2)},
      {Eigen::Vector2f(0.0f, 0.0f), Eigen::Vector2f(1.0f, 0.0f), Eigen::Vector2f(0.25f, 0.75f)});
  const std::string path = scratch_.path("triangle.glb");
  saveMesh(triangle, path);
  const Gltf gltf = readGlb(path);
  const std::vector<float> uvs = accessor<float>(
      gltf, gltf.json["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"].as<int>(), 5126,
      "VEC2", 2);
  EXPECT_EQ(uvs, (std::vector<float>{0.0f, 1.0f, 1.0f, 1.0f, 0.25f, 0.25f}));
  EXPECT_FALSE(gltf.json["materials"][0]["normalTexture"]);
  EXPECT_FALSE(gltf.json["images"]);
  // assimp (which flips v on import) gives the saved UVs back.
  const TexturedMesh loaded = TexturedMesh::load(path);
  ASSERT_EQ(loaded.uvs().size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_LE((loaded.uvs()[i] - triangle.uvs()[i]).norm(), 1e-6f) << "vertex " << i;
  }
}

TEST(GltfUri, EncodesWhatIsNotUnreservedAndDecodesBack) {
  EXPECT_EQ(detail::uriEncodePath("textures/sphere normal.png"), "textures/sphere%20normal.png");
  EXPECT_EQ(detail::uriEncodePath("a%b#c?d:e.png"), "a%25b%23c%3Fd%3Ae.png");
  EXPECT_EQ(detail::uriEncodePath("../x-y_z~1.png"), "../x-y_z~1.png");
  EXPECT_EQ(detail::uriEncodePath("\xc3\xa9.png"), "%C3%A9.png");
  for (const std::string name : {"textures/sphere normal.png", "a%b#c?d:e.png", "\xc3\xa9 1.png"}) {
    EXPECT_EQ(detail::uriDecodePath(detail::uriEncodePath(name)), name);
  }
  EXPECT_EQ(detail::uriDecodePath("100%"), "100%");
  EXPECT_EQ(detail::uriDecodePath("%zz%4"), "%zz%4");
}

}  // namespace
}  // namespace norm2tex
