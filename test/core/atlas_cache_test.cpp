#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>
#include <opencv2/imgcodecs.hpp>

#include "norm2tex/common/error.hpp"
#include "norm2tex/texture/analytic_surface.hpp"
#include "norm2tex/texture/atlas_cache.hpp"
#include "norm2tex/texture/normal_encoding.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {
namespace fs = std::filesystem;

class AtlasCacheTest : public testing::Test {
 protected:
  void SetUp() override {
    const cv::Size size(64, 48);
    AnalyticSurface s = makeWaves(size, {{2.0, 21.0, 0.4, 0.0}});
    s += makeBumps(size, {{{20, 20}, 5, 4}});
    normal_map_path_ = dir_.path("normal.png");
    ASSERT_TRUE(cv::imwrite(normal_map_path_,
                            encodeNormalMap(s.dx, s.dy, NormalConvention::kOpenGL, CV_8U)));
  }
  std::string readFile(const std::string& path) {
    std::ifstream file(path);
    std::stringstream text;
    text << file.rdbuf();
    return text.str();
  }
  test::ScratchDirectory dir_;
  std::string normal_map_path_;
};

TEST_F(AtlasCacheTest, MeshBakesAreCachedUnderTheMeshToo) {
  // A 20 x 15 mm plate whose UVs cover the texture once.
  const auto plate = [](float width_m) {
    return TexturedMesh({{0, 0, 0}, {width_m, 0, 0}, {width_m, 0.015f, 0}, {0, 0.015f, 0}},
                        {{0, 1, 2}, {0, 2, 3}}, {{0, 0}, {1, 0}, {1, 1}, {0, 1}});
  };
  const TexturedMesh mesh = plate(0.02f), wider = plate(0.04f);
  const AtlasCache cache(dir_.path("cache"));
  BakeOptions options;
  options.physical_scale = true;  // needs the mesh's mm per texel
  const AtlasCache::Result first = cache.loadOrBake(normal_map_path_, "", options, {}, &mesh);
  EXPECT_FALSE(first.was_cached);
  EXPECT_NEAR(first.mesh_report.mm_per_texel, std::sqrt(20.0 / 64 * 15.0 / 48), 1e-3);
  const AtlasCache::Result second = cache.loadOrBake(normal_map_path_, "", options, {}, &mesh);
  EXPECT_TRUE(second.was_cached);
  EXPECT_EQ(cv::norm(first.atlas.heights(), second.atlas.heights(), cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::countNonZero(first.atlas.islandLabels() != second.atlas.islandLabels()), 0);
  // Another mesh (other scale: other heights in mm) or none: other entries.
  EXPECT_NE(cache.key(normal_map_path_, "", options, &mesh),
            cache.key(normal_map_path_, "", options, &wider));
  EXPECT_NE(cache.key(normal_map_path_, "", options, &mesh),
            cache.key(normal_map_path_, "", options));
  EXPECT_FALSE(cache.loadOrBake(normal_map_path_, "", options, {}, &wider).was_cached);
}

TEST_F(AtlasCacheTest, EmbeddedTextureIsCachedWithTheBakesIslands) {
  // A GLB's embedded normal texture ("*0") arrives as the encoded file's bytes. Two charts of a
  // 20 x 15 mm plate, its halves, meet at a seam (x = 10 mm) and lie apart in the texture; the
  // map has no alpha, so only the mesh makes them two islands.
  const TexturedMesh mesh({{0, 0, 0},
                           {0.01f, 0, 0},
                           {0.01f, 0.015f, 0},
                           {0, 0.015f, 0},
                           {0.01f, 0, 0},
                           {0.02f, 0, 0},
                           {0.02f, 0.015f, 0},
                           {0.01f, 0.015f, 0}},
                          {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}},
                          {{0.05f, 0.1f},
                           {0.45f, 0.1f},
                           {0.45f, 0.9f},
                           {0.05f, 0.9f},
                           {0.55f, 0.1f},
                           {0.95f, 0.1f},
                           {0.95f, 0.9f},
                           {0.55f, 0.9f}});
  std::ifstream file(normal_map_path_, std::ios::binary);
  const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(file)),
                                         std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 100u);
  const std::string what = "the mesh's normal texture '*0'";
  const AtlasCache cache(dir_.path("cache"));
  BakeOptions options;
  options.physical_scale = true;  // as for a mesh's own texture: heights in mm

  const AtlasCache::Result first = cache.loadOrBake(bytes, what, options, {}, &mesh);
  EXPECT_FALSE(first.was_cached);
  EXPECT_TRUE(first.store_error.empty()) << first.store_error;
  EXPECT_EQ(first.mesh_report.chart_count, 2);
  EXPECT_EQ(first.atlas.islandCount(), 2) << "the mesh's charts, not the mask's one island";
  const HeightAtlas direct = bakeHeightAtlasForMesh(
      NormalMap::fromImage(cv::imread(normal_map_path_, cv::IMREAD_UNCHANGED)), mesh, options);
  EXPECT_EQ(cv::norm(first.atlas.heights(), direct.heights(), cv::NORM_INF), 0.0);

  const AtlasCache::Result second = cache.loadOrBake(bytes, what, options, {}, &mesh);
  EXPECT_TRUE(second.was_cached);
  EXPECT_EQ(cv::norm(first.atlas.heights(), second.atlas.heights(), cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::countNonZero(first.atlas.valid() != second.atlas.valid()), 0);
  EXPECT_EQ(cv::countNonZero(first.atlas.islandLabels() != second.atlas.islandLabels()), 0);
  EXPECT_EQ(second.atlas.islandCount(), 2);

  // The entry names the embedded texture; the same bytes in a file share it.
  const std::string key = cache.key(bytes, options, &mesh);
  EXPECT_NE(readFile(dir_.path("cache/" + key + ".yaml")).find(what), std::string::npos);
  EXPECT_EQ(key, cache.key(normal_map_path_, "", options, &mesh));
  // Other bytes, another mesh, other options: other entries.
  std::vector<unsigned char> changed = bytes;
  changed[changed.size() / 2] ^= 1;
  EXPECT_NE(key, cache.key(changed, options, &mesh));
  EXPECT_NE(key, cache.key(bytes, options));
  BakeOptions other = options;
  other.relief_cutoff_mm = 1.0;
  EXPECT_NE(key, cache.key(bytes, other, &mesh));

  // Truncated bytes: refused, naming the texture (never decoded half grey, never cached).
  const std::vector<unsigned char> truncated(bytes.begin(), bytes.begin() + bytes.size() / 2);
  test::expectError([&] { cache.loadOrBake(truncated, what, options, {}, &mesh); }, {"*0"});
  EXPECT_FALSE(cache.load(cache.key(truncated, options, &mesh)).has_value());
}

TEST_F(AtlasCacheTest, SecondLoadComesFromTheCacheBitForBit) {
  const AtlasCache cache(dir_.path("cache"));
  const AtlasCache::Result first = cache.loadOrBake(normal_map_path_, "", {});
  EXPECT_FALSE(first.was_cached);
  EXPECT_TRUE(first.store_error.empty()) << first.store_error;
  const AtlasCache::Result second = cache.loadOrBake(normal_map_path_, "", {});
  EXPECT_TRUE(second.was_cached);
  EXPECT_EQ(cv::norm(first.atlas.heights(), second.atlas.heights(), cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::countNonZero(first.atlas.valid() != second.atlas.valid()), 0);
  EXPECT_EQ(second.atlas.islandCount(), first.atlas.islandCount());
}

TEST_F(AtlasCacheTest, MetadataRecordsSourceConventionAndParameters) {
  const AtlasCache cache(dir_.path("cache"));
  BakeOptions options;
  options.normal_map.convention = NormalConvention::kDirectX;
  options.range = HeightRange::kRemove;
  cache.loadOrBake(normal_map_path_, "", options);
  const std::string yaml =
      readFile(dir_.path("cache/" + cache.key(normal_map_path_, "", options) + ".yaml"));
  EXPECT_NE(yaml.find("source_hash"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("normal.png"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("directx"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("sigma_fine=0.34999"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("0,-1"), std::string::npos) << yaml;
}

TEST_F(AtlasCacheTest, KeyFollowsContentAndEveryOption) {
  const AtlasCache cache(dir_.path("cache"));
  const std::string base = cache.key(normal_map_path_, "", {});
  EXPECT_EQ(base, cache.key(normal_map_path_, "", {})) << "stable";
  // Same bytes under another name: same entry.
  fs::copy_file(normal_map_path_, dir_.path("renamed.png"));
  EXPECT_EQ(base, cache.key(dir_.path("renamed.png"), "", {}));
  BakeOptions o;
  o.alpha = 0.3;
  EXPECT_NE(base, cache.key(normal_map_path_, "", o));
  o = {};
  o.normal_map.convention = NormalConvention::kDirectX;
  EXPECT_NE(base, cache.key(normal_map_path_, "", o));
  o = {};
  o.range = HeightRange::kAdd;
  EXPECT_NE(base, cache.key(normal_map_path_, "", o));
  // One changed byte in the image file: a different entry.
  cv::Mat image = cv::imread(normal_map_path_, cv::IMREAD_UNCHANGED);
  image.at<cv::Vec3b>(3, 3)[0] ^= 1;
  cv::imwrite(normal_map_path_, image);
  EXPECT_NE(base, cache.key(normal_map_path_, "", {}));
}

TEST_F(AtlasCacheTest, DamagedEntryIsAMissAndGetsReplaced) {
  const AtlasCache cache(dir_.path("cache"));
  cache.loadOrBake(normal_map_path_, "", {});
  const std::string key = cache.key(normal_map_path_, "", {});
  std::ofstream(dir_.path("cache/" + key + ".tiff"), std::ios::trunc) << "garbage";
  EXPECT_FALSE(cache.load(key).has_value());
  const AtlasCache::Result again = cache.loadOrBake(normal_map_path_, "", {});
  EXPECT_FALSE(again.was_cached);
  EXPECT_TRUE(cache.load(key).has_value());
}

TEST_F(AtlasCacheTest, EntryWithoutMetadataDoesNotCount) {
  // The yaml is written last: without it, an interrupted store is invisible.
  const AtlasCache cache(dir_.path("cache"));
  cache.loadOrBake(normal_map_path_, "", {});
  const std::string key = cache.key(normal_map_path_, "", {});
  fs::remove(dir_.path("cache/" + key + ".yaml"));
  EXPECT_FALSE(cache.load(key).has_value());
}

TEST_F(AtlasCacheTest, UnwritableCacheStillReturnsTheAtlas) {
  if (geteuid() == 0) {
    // root ignores permissions: use a path under a regular file instead.
    std::ofstream(dir_.path("not_a_dir")) << "x";
  } else {
    fs::create_directory(dir_.path("not_a_dir"));
    fs::permissions(dir_.path("not_a_dir"), fs::perms::owner_read | fs::perms::owner_exec);
  }
  const AtlasCache cache(dir_.path("not_a_dir/cache"));
  const AtlasCache::Result result = cache.loadOrBake(normal_map_path_, "", {});
  EXPECT_FALSE(result.atlas.empty());
  EXPECT_FALSE(result.store_error.empty());
  EXPECT_FALSE(result.was_cached);
}

TEST_F(AtlasCacheTest, MissingNormalMapIsAClearError) {
  const AtlasCache cache(dir_.path("cache"));
  try {
    cache.loadOrBake(dir_.path("nope.png"), "", {});
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("nope.png"), std::string::npos) << e.what();
  }
}

TEST(AtlasCacheDirectory, EnvironmentChoosesTheDefault) {
  setenv("NORM2TEX_CACHE_DIR", "/tmp/explicit_cache", 1);
  EXPECT_EQ(AtlasCache::defaultDirectory(), "/tmp/explicit_cache");
  unsetenv("NORM2TEX_CACHE_DIR");
  setenv("XDG_CACHE_HOME", "/tmp/xdg", 1);
  EXPECT_EQ(AtlasCache::defaultDirectory(), "/tmp/xdg/norm2tex");
  unsetenv("XDG_CACHE_HOME");
}

}  // namespace
}  // namespace norm2tex
