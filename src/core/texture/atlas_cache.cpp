#include "norm2tex/texture/atlas_cache.hpp"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include <yaml-cpp/yaml.h>
#include <opencv2/imgcodecs.hpp>

#include "norm2tex/common/error.hpp"
#include "norm2tex/common/file_hash.hpp"
#include "norm2tex/common/image_io.hpp"

namespace norm2tex {
namespace fs = std::filesystem;
namespace {

// Bump when the bake's output for the same input and options changes.
constexpr int kFormatVersion = 2;  // 2: exact least squares, island labels, relief cutoff

std::string describeOptions(const BakeOptions& o) {
  std::ostringstream text;
  text << std::setprecision(17) << "convention=" << toString(o.normal_map.convention)
       << ";min_nz=" << o.normal_map.min_nz << ";alpha_threshold=" << o.normal_map.alpha_threshold
       << ";sigma_fine=" << o.sigma_fine << ";sigma_coarse=" << o.sigma_coarse
       << ";alpha=" << o.alpha << ";percentile_low=" << o.percentile_low
       << ";percentile_high=" << o.percentile_high << ";range=" << toString(o.range) << ";boundary="
       << (o.integration.boundary == PoissonBoundary::kNeumann ? "neumann" : "periodic")
       << ";tolerance=" << o.integration.tolerance
       << ";max_iterations=" << o.integration.max_iterations
       << ";remove_mean_slope=" << o.remove_mean_slope << ";relief_cutoff_mm=" << o.relief_cutoff_mm
       << ";relief_cutoff_texels=" << o.relief_cutoff_texels << ";mm_per_texel=" << o.mm_per_texel
       << ";physical_scale=" << o.physical_scale;
  return text.str();
}

std::string entryPath(const std::string& directory, const std::string& key,
                      const std::string& suffix) {
  return (fs::path(directory) / (key + suffix)).string();
}

}  // namespace

AtlasCache::AtlasCache(std::string directory) : directory_(std::move(directory)) {
  if (directory_.empty()) throw Error("AtlasCache: empty cache directory");
}

std::string AtlasCache::defaultDirectory() {
  if (const char* explicit_dir = std::getenv("NORM2TEX_CACHE_DIR"); explicit_dir && *explicit_dir) {
    return explicit_dir;
  }
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) {
    return (fs::path(xdg) / "norm2tex").string();
  }
  const char* home = std::getenv("HOME");
  return (fs::path(home && *home ? home : "/tmp") / ".cache" / "norm2tex").string();
}

namespace {

/// The key from the content hashes (hex) of the normal map and the mask ("" for none).
std::string keyOf(const std::string& normal_map_hash, const std::string& mask_hash,
                  const BakeOptions& options, const TexturedMesh* mesh) {
  std::uint64_t hash = fnv1a64("norm2tex-atlas-v" + std::to_string(kFormatVersion));
  hash = fnv1a64(normal_map_hash, hash);
  hash = fnv1a64(mask_hash.empty() ? std::string("no-mask") : mask_hash, hash);
  hash = fnv1a64(describeOptions(options), hash);
  if (mesh != nullptr) {
    // What a mesh bake depends on: UV layout (charts), 3-D areas (scale) and seams.
    const auto bytes = [](const auto& items) {
      return std::string(reinterpret_cast<const char*>(items.data()),
                         items.size() * sizeof(items[0]));
    };
    hash = fnv1a64("mesh", hash);
    hash = fnv1a64(bytes(mesh->vertices()), hash);
    hash = fnv1a64(bytes(mesh->triangles()), hash);
    hash = fnv1a64(bytes(mesh->uvs()), hash);
  }
  return toHex(hash);
}

/// hashFile() of a file holding `bytes`: an embedded texture and the same bytes in a file
/// share their entry.
std::string hashBytes(const std::vector<unsigned char>& bytes) {
  return toHex(fnv1a64(std::string(bytes.begin(), bytes.end())));
}

}  // namespace

std::string AtlasCache::key(const std::string& normal_map_path, const std::string& mask_path,
                            const BakeOptions& options, const TexturedMesh* mesh) const {
  return keyOf(hashFile(normal_map_path), mask_path.empty() ? "" : hashFile(mask_path), options,
               mesh);
}

std::string AtlasCache::key(const std::vector<unsigned char>& encoded_normal_map,
                            const BakeOptions& options, const TexturedMesh* mesh) const {
  return keyOf(hashBytes(encoded_normal_map), "", options, mesh);
}

std::optional<HeightAtlas> AtlasCache::load(const std::string& key) const {
  const std::string metadata_path = entryPath(directory_, key, ".yaml");
  std::error_code ec;
  if (!fs::exists(metadata_path, ec)) return std::nullopt;  // written last: marks completion
  try {
    const YAML::Node metadata = YAML::LoadFile(metadata_path);
    if (metadata["format_version"].as<int>() != kFormatVersion) return std::nullopt;
    const cv::Mat heights = cv::imread(entryPath(directory_, key, ".tiff"), cv::IMREAD_UNCHANGED);
    const cv::Mat valid =
        cv::imread(entryPath(directory_, key, ".valid.png"), cv::IMREAD_GRAYSCALE);
    const cv::Mat labels =
        cv::imread(entryPath(directory_, key, ".islands.png"), cv::IMREAD_UNCHANGED);
    if (heights.empty() || heights.type() != CV_32FC1 || valid.size() != heights.size() ||
        labels.type() != CV_16UC1 || labels.size() != heights.size() ||
        heights.rows != metadata["rows"].as<int>() || heights.cols != metadata["cols"].as<int>()) {
      return std::nullopt;
    }
    cv::Mat1i island_labels;
    labels.convertTo(island_labels, CV_32S);
    return HeightAtlas(heights, valid, island_labels);
  } catch (const std::exception&) {
    return std::nullopt;  // a damaged entry is a miss; the next store replaces it
  }
}

void AtlasCache::store(const std::string& key, const HeightAtlas& atlas,
                       const std::string& normal_map_path, const std::string& mask_path,
                       const BakeOptions& options) const {
  storeEntry(key, atlas, fs::absolute(normal_map_path).string(), hashFile(normal_map_path),
             mask_path.empty() ? std::string() : fs::absolute(mask_path).string(),
             mask_path.empty() ? std::string() : hashFile(mask_path), options);
}

void AtlasCache::storeEntry(const std::string& key, const HeightAtlas& atlas,
                            const std::string& source, const std::string& source_hash,
                            const std::string& mask_path, const std::string& mask_hash,
                            const BakeOptions& options) const {
  std::error_code ec;
  fs::create_directories(directory_, ec);
  if (ec) throw Error("cannot create cache directory '" + directory_ + "': " + ec.message());
  writeImage(entryPath(directory_, key, ".tiff"), atlas.heights());
  writeImage(entryPath(directory_, key, ".valid.png"), atlas.valid());
  // Island labels as 16-bit PNG: they are the bake's islands, not recomputable from the mask
  // once islands come from a mesh's UV charts.
  if (atlas.islandCount() > 65535) {
    throw Error("cannot cache an atlas of " + std::to_string(atlas.islandCount()) +
                " islands (at most 65535)");
  }
  cv::Mat labels;
  atlas.islandLabels().convertTo(labels, CV_16U);
  writeImage(entryPath(directory_, key, ".islands.png"), labels);

  YAML::Emitter yaml;
  yaml << YAML::BeginMap;
  yaml << YAML::Key << "format_version" << YAML::Value << kFormatVersion;
  yaml << YAML::Key << "key" << YAML::Value << key;
  yaml << YAML::Key << "source_path" << YAML::Value << source;
  yaml << YAML::Key << "source_hash" << YAML::Value << source_hash;
  yaml << YAML::Key << "mask_path" << YAML::Value << mask_path;
  yaml << YAML::Key << "mask_hash" << YAML::Value << mask_hash;
  yaml << YAML::Key << "parameters" << YAML::Value << describeOptions(options);
  yaml << YAML::Key << "convention" << YAML::Value << toString(options.normal_map.convention);
  yaml << YAML::Key << "range" << YAML::Value << toString(options.range);
  yaml << YAML::Key << "rows" << YAML::Value << atlas.rows();
  yaml << YAML::Key << "cols" << YAML::Value << atlas.cols();
  yaml << YAML::Key << "island_count" << YAML::Value << atlas.islandCount();
  yaml << YAML::EndMap;

  const std::string final_path = entryPath(directory_, key, ".yaml");
  const std::string temporary = final_path + ".tmp";
  {
    std::ofstream file(temporary);
    file << yaml.c_str() << "\n";
    file.flush();
    if (!file) {
      fs::remove(temporary, ec);
      throw Error("cannot write cache metadata '" + temporary + "' (disk full?)");
    }
  }
  fs::rename(temporary, final_path, ec);
  if (ec) throw Error("cannot write cache metadata '" + final_path + "': " + ec.message());
}

namespace {

/// A mesh bake learns mm per texel from the mesh (and checks the physical scale then).
void validateForBake(const BakeOptions& options, const TexturedMesh* mesh) {
  BakeOptions checked = options;
  if (mesh != nullptr) checked.physical_scale = false;
  validate(checked);
}

HeightAtlas bake(const NormalMap& normal_map, const BakeOptions& options,
                 const BakeProgress& progress, const TexturedMesh* mesh, MeshBakeReport& report) {
  return mesh != nullptr ? bakeHeightAtlasForMesh(normal_map, *mesh, options, progress, &report)
                         : bakeHeightAtlas(normal_map, options, progress);
}

}  // namespace

AtlasCache::Result AtlasCache::loadOrBake(const std::string& normal_map_path,
                                          const std::string& mask_path, const BakeOptions& options,
                                          const BakeProgress& progress,
                                          const TexturedMesh* mesh) const {
  validateForBake(options, mesh);
  Result result;
  const std::string cache_key = key(normal_map_path, mask_path, options, mesh);
  if (std::optional<HeightAtlas> cached = load(cache_key)) {
    result.atlas = std::move(*cached);
    result.was_cached = true;
    return result;
  }
  const NormalMap normal_map = NormalMap::load(normal_map_path, options.normal_map, mask_path);
  result.atlas = bake(normal_map, options, progress, mesh, result.mesh_report);
  try {
    store(cache_key, result.atlas, normal_map_path, mask_path, options);
  } catch (const Error& e) {
    result.store_error = e.what();
  }
  return result;
}

AtlasCache::Result AtlasCache::loadOrBake(const std::vector<unsigned char>& encoded_normal_map,
                                          const std::string& what, const BakeOptions& options,
                                          const BakeProgress& progress,
                                          const TexturedMesh* mesh) const {
  validateForBake(options, mesh);
  Result result;
  const std::string cache_key = key(encoded_normal_map, options, mesh);
  if (std::optional<HeightAtlas> cached = load(cache_key)) {
    result.atlas = std::move(*cached);
    result.was_cached = true;
    return result;
  }
  const NormalMap normal_map = [&] {
    const cv::Mat image = decodeImage(encoded_normal_map, cv::IMREAD_UNCHANGED, what);
    try {
      return NormalMap::fromImage(image, options.normal_map);
    } catch (const Error& e) {
      throw Error(what + ": " + e.what());
    }
  }();
  result.atlas = bake(normal_map, options, progress, mesh, result.mesh_report);
  try {
    storeEntry(cache_key, result.atlas, what, hashBytes(encoded_normal_map), "", "", options);
  } catch (const Error& e) {
    result.store_error = e.what();
  }
  return result;
}

}  // namespace norm2tex
