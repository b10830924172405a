// glTF 2.0 writer for saveMesh (see gltf_writer.hpp).
#include "mesh/gltf_writer.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <vector>

#include "common/json_writer.hpp"  // jsonString: file names may hold quotes or backslashes
#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace detail {
namespace {

namespace fs = std::filesystem;

// glTF enumerations (glTF 2.0 specification, section 5).
constexpr int kFloat = 5126;
constexpr int kUnsignedInt = 5125;
constexpr int kArrayBuffer = 34962;
constexpr int kElementArrayBuffer = 34963;
constexpr int kTriangles = 4;
// GLB container (section 4.4): magic "glTF", version 2, chunk types "JSON" and "BIN\0".
constexpr std::uint32_t kGlbMagic = 0x46546C67u;
constexpr std::uint32_t kJsonChunk = 0x4E4F534Au;
constexpr std::uint32_t kBinChunk = 0x004E4942u;

// Shortest text that reads back as the same float: min/max must equal the buffer's values.
std::string number(float value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.9g", static_cast<double>(value));
  return text;
}

void append(std::vector<unsigned char>& buffer, const void* data, size_t bytes) {
  const auto* begin = static_cast<const unsigned char*>(data);
  buffer.insert(buffer.end(), begin, begin + bytes);
}

void appendU32(std::vector<unsigned char>& buffer, std::uint32_t value) {
  // glTF is little-endian; so is every platform the package builds on (x86-64, arm64).
  append(buffer, &value, sizeof(value));
}

// Per-vertex normals: the sum of the adjacent triangles' cross products (area-weighted),
// normalised; +z for a vertex of degenerate triangles only (glTF wants unit normals).
std::vector<Eigen::Vector3f> vertexNormals(const TexturedMesh& mesh) {
  std::vector<Eigen::Vector3d> sums(mesh.vertices().size(), Eigen::Vector3d::Zero());
  for (const Eigen::Vector3i& t : mesh.triangles()) {
    const Eigen::Vector3d a = mesh.vertices()[t[0]].cast<double>();
    const Eigen::Vector3d n =
        (mesh.vertices()[t[1]].cast<double>() - a).cross(mesh.vertices()[t[2]].cast<double>() - a);
    for (int k = 0; k < 3; ++k) sums[t[k]] += n;
  }
  std::vector<Eigen::Vector3f> normals;
  normals.reserve(sums.size());
  for (const Eigen::Vector3d& sum : sums) {
    const double length = sum.norm();
    normals.push_back(length > 0.0 && std::isfinite(length)
                          ? Eigen::Vector3f((sum / length).cast<float>())
                          : Eigen::Vector3f::UnitZ());
  }
  return normals;
}

std::string base64(const std::vector<unsigned char>& bytes) {
  static const char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const size_t left = std::min<size_t>(3, bytes.size() - i);
    std::uint32_t group = static_cast<std::uint32_t>(bytes[i]) << 16;
    if (left > 1) group |= static_cast<std::uint32_t>(bytes[i + 1]) << 8;
    if (left > 2) group |= bytes[i + 2];
    for (size_t k = 0; k < 4; ++k) {
      out += k <= left ? kAlphabet[(group >> (18 - 6 * k)) & 63] : '=';
    }
  }
  return out;
}

struct View {
  size_t offset = 0, bytes = 0;
  int target = 0;
};

}  // namespace

std::string uriEncodePath(const std::string& path) {
  std::string out;
  for (const char c : path) {
    const auto byte = static_cast<unsigned char>(c);
    if (std::isalnum(byte) != 0 && byte < 0x80) {
      out += c;
    } else if (c == '-' || c == '.' || c == '_' || c == '~' || c == '/') {
      out += c;
    } else {
      char escape[4];
      std::snprintf(escape, sizeof(escape), "%%%02X", static_cast<unsigned>(byte));
      out += escape;
    }
  }
  return out;
}

std::string uriDecodePath(const std::string& uri) {
  const auto hex = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  std::string out;
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && hex(uri[i + 1]) >= 0 && hex(uri[i + 2]) >= 0) {
      out += static_cast<char>(hex(uri[i + 1]) * 16 + hex(uri[i + 2]));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

void writeGltf(const TexturedMesh& mesh, const std::string& path, bool binary,
               const std::string& normal_texture_uri, const std::string& material_name) {
  const std::string what = "mesh '" + path + "'";
  const std::vector<Eigen::Vector3f>& vertices = mesh.vertices();
  const size_t vertex_count = vertices.size(), triangle_count = mesh.triangles().size();
  if (vertex_count > std::numeric_limits<std::uint32_t>::max() / 2 ||
      triangle_count > std::numeric_limits<std::uint32_t>::max() / 24) {
    throw Error("saveMesh: cannot write " + what + ": too large for one glTF buffer");
  }

  // The buffer: positions, normals, UVs, indices. Every element is 4 bytes, so each view
  // starts 4-aligned as accessors require.
  std::vector<unsigned char> buffer;
  std::vector<View> views;
  const auto addView = [&](const void* data, size_t bytes, int target) {
    views.push_back(View{buffer.size(), bytes, target});
    append(buffer, data, bytes);
  };
  Eigen::Vector3f low = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
  Eigen::Vector3f high = -low;
  for (const Eigen::Vector3f& v : vertices) {
    low = low.cwiseMin(v);
    high = high.cwiseMax(v);
  }
  addView(vertices.data(), vertex_count * sizeof(float) * 3, kArrayBuffer);
  const std::vector<Eigen::Vector3f> normals = vertexNormals(mesh);
  addView(normals.data(), vertex_count * sizeof(float) * 3, kArrayBuffer);
  if (mesh.hasUvs()) {
    std::vector<float> uvs;
    uvs.reserve(2 * vertex_count);
    for (const Eigen::Vector2f& uv : mesh.uvs()) {
      uvs.push_back(uv.x());
      uvs.push_back(1.0f - uv.y());  // glTF's v runs down the image
    }
    addView(uvs.data(), uvs.size() * sizeof(float), kArrayBuffer);
  }
  std::vector<std::uint32_t> indices;
  indices.reserve(3 * triangle_count);
  for (const Eigen::Vector3i& t : mesh.triangles()) {
    for (int k = 0; k < 3; ++k) indices.push_back(static_cast<std::uint32_t>(t[k]));
  }
  addView(indices.data(), indices.size() * sizeof(std::uint32_t), kElementArrayBuffer);

  const fs::path file(path);
  // The buffer of a .gltf goes to <stem>.bin unless the name needs percent-encoding in a URI:
  // assimp does not decode buffer URIs ("my%20mesh.bin" is not found), so such a buffer is
  // embedded as a base64 data URI instead, which every reader takes.
  const std::string bin_name = file.stem().string() + ".bin";
  const bool bin_beside = !binary && uriEncodePath(bin_name) == bin_name;
  std::ostringstream json;
  json << "{\"asset\":{\"version\":\"2.0\",\"generator\":\"norm2tex\"},"
       << "\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
       << "\"nodes\":[{\"name\":\"norm2tex\",\"mesh\":0}],"
       << "\"meshes\":[{\"name\":\"norm2tex\",\"primitives\":[{\"attributes\":{"
       << "\"POSITION\":0,\"NORMAL\":1" << (mesh.hasUvs() ? ",\"TEXCOORD_0\":2" : "")
       << "},\"indices\":" << (mesh.hasUvs() ? 3 : 2) << ",\"material\":0,\"mode\":" << kTriangles
       << "}]}],";
  json << "\"materials\":[{\"name\":" << jsonString(material_name) << ",\"pbrMetallicRoughness\":{"
       << "\"metallicFactor\":0,\"roughnessFactor\":1}";
  if (!normal_texture_uri.empty()) json << ",\"normalTexture\":{\"index\":0}";
  json << ",\"doubleSided\":false}],";
  if (!normal_texture_uri.empty()) {
    // Linear filtering with mipmaps, repeat: the glTF defaults, written out for old readers.
    json << "\"samplers\":[{\"magFilter\":9729,\"minFilter\":9987,\"wrapS\":10497,"
         << "\"wrapT\":10497}],\"images\":[{\"uri\":"
         << jsonString(uriEncodePath(normal_texture_uri))
         << "}],\"textures\":[{\"sampler\":0,\"source\":0}],";
  }
  json << "\"buffers\":[{\"byteLength\":" << buffer.size();
  if (bin_beside) {
    json << ",\"uri\":" << jsonString(bin_name);
  } else if (!binary) {
    json << ",\"uri\":\"data:application/octet-stream;base64," << base64(buffer) << "\"";
  }
  json << "}],\"bufferViews\":[";
  for (size_t i = 0; i < views.size(); ++i) {
    json << (i ? "," : "") << "{\"buffer\":0,\"byteOffset\":" << views[i].offset
         << ",\"byteLength\":" << views[i].bytes << ",\"target\":" << views[i].target << "}";
  }
  json << "],\"accessors\":[";
  json << "{\"bufferView\":0,\"componentType\":" << kFloat << ",\"count\":" << vertex_count
       << ",\"type\":\"VEC3\",\"min\":[" << number(low.x()) << "," << number(low.y()) << ","
       << number(low.z()) << "],\"max\":[" << number(high.x()) << "," << number(high.y()) << ","
       << number(high.z()) << "]},";
  json << "{\"bufferView\":1,\"componentType\":" << kFloat << ",\"count\":" << vertex_count
       << ",\"type\":\"VEC3\"},";
  int view = 2;
  if (mesh.hasUvs()) {
    json << "{\"bufferView\":" << view++ << ",\"componentType\":" << kFloat
         << ",\"count\":" << vertex_count << ",\"type\":\"VEC2\"},";
  }
  json << "{\"bufferView\":" << view << ",\"componentType\":" << kUnsignedInt
       << ",\"count\":" << indices.size() << ",\"type\":\"SCALAR\"}]}";
  std::string json_text = json.str();

  const auto writeFile = [&](const fs::path& target, const std::vector<unsigned char>& bytes) {
    std::ofstream out(target, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) throw Error("saveMesh: cannot write '" + target.string() + "' (permissions?)");
  };
  if (!binary) {
    if (bin_beside) writeFile(file.parent_path() / bin_name, buffer);
    writeFile(file, std::vector<unsigned char>(json_text.begin(), json_text.end()));
    return;
  }
  // GLB: both chunks padded to 4 bytes, JSON with spaces and BIN with zeros (section 4.4.3).
  while (json_text.size() % 4 != 0) json_text += ' ';
  while (buffer.size() % 4 != 0) buffer.push_back(0);
  std::vector<unsigned char> glb;
  const size_t total = 12 + 8 + json_text.size() + 8 + buffer.size();
  if (total > std::numeric_limits<std::uint32_t>::max()) {
    throw Error("saveMesh: cannot write " + what + ": larger than a .glb can hold (4 GB)");
  }
  glb.reserve(total);
  appendU32(glb, kGlbMagic);
  appendU32(glb, 2);
  appendU32(glb, static_cast<std::uint32_t>(total));
  appendU32(glb, static_cast<std::uint32_t>(json_text.size()));
  appendU32(glb, kJsonChunk);
  append(glb, json_text.data(), json_text.size());
  appendU32(glb, static_cast<std::uint32_t>(buffer.size()));
  appendU32(glb, kBinChunk);
  append(glb, buffer.data(), buffer.size());
  writeFile(file, glb);
}

}  // namespace detail
}  // namespace norm2tex
