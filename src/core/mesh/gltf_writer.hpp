#pragma once
// glTF 2.0 output of saveMesh, written by the package itself rather than assimp's exporter:
// assimp 5.0.1 (Ubuntu 20.04, Debian 11) writes TEXCOORD_0 without glTF's flip of v, so the
// same call gave mirrored textures there and correct ones on assimp >= 5.1. Written here, the
// file is the same on every platform.

#include <string>

#include "norm2tex/mesh/textured_mesh.hpp"

namespace norm2tex {
namespace detail {

/// Writes `mesh` as glTF 2.0 to `path`: a binary .glb when `binary`, else a .gltf (JSON) with
/// its buffer in <stem>.bin beside it (embedded as a base64 data URI instead when <stem> holds
/// characters a URI must escape, such as spaces: assimp does not decode buffer URIs). One scene,
/// one node, one mesh of one triangle primitive: POSITION, NORMAL (area-weighted vertex normals),
/// TEXCOORD_0 when the mesh has UVs, and UNSIGNED_INT indices. UVs are stored in glTF's convention
/// (origin at the image's top left): v_gltf = 1 - v, so readers that follow the specification (and
/// assimp's importer, which flips back) see the texture the right way up. One material named
/// `material_name`; when `normal_texture_uri` is not empty, it is the material's normalTexture, an
/// image referenced by that relative path (percent-encoded as a URI), not embedded. Throws Error
/// naming the file when it cannot be written.
void writeGltf(const TexturedMesh& mesh, const std::string& path, bool binary,
               const std::string& normal_texture_uri, const std::string& material_name);

/// `path` as a URI reference: bytes other than letters, digits, '-', '.', '_', '~' and '/' are
/// percent-encoded ("sphere normal.png" -> "sphere%20normal.png").
std::string uriEncodePath(const std::string& path);

/// The inverse of uriEncodePath for any URI reference: "%XX" decoded, other bytes kept; a '%'
/// not followed by two hex digits is kept as it is.
std::string uriDecodePath(const std::string& uri);

}  // namespace detail
}  // namespace norm2tex
