// Where an object's texture comes from: a mesh's own normal texture, embedded in a GLB or a
// file next to it, and what happens when it cannot be used.
#include <malloc.h>
#include <sys/resource.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <future>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "norm2tex/common/error.hpp"
#include "norm2tex/common/huge_pages.hpp"
#include "norm2tex/common/memory_reuse.hpp"
#include "norm2tex/mesh/mesh_primitives.hpp"
#include "norm2tex/render/object_texture.hpp"
#include "norm2tex/render/object_texture_cache.hpp"
#include "norm2tex/render/tactile_renderer.hpp"
#include "norm2tex/texture/analytic_surface.hpp"
#include "norm2tex/texture/height_atlas_baker.hpp"
#include "norm2tex/texture/mesh_bake.hpp"
#include "norm2tex/texture/normal_encoding.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

void append(std::vector<unsigned char>& out, const void* data, size_t size) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  out.insert(out.end(), bytes, bytes + size);
}

void appendU32(std::vector<unsigned char>& out, std::uint32_t value) {
  append(out, &value, 4);  // GLB is little-endian, like x86
}

/// A binary glTF of one 20 x 20 mm square in the z = 0 plane, UVs over [0, 1]^2, whose material's
/// normal texture is `png` embedded in the file ("*0") or, when `png` is empty, an external
/// image `uri`.
void writeSquareGlb(const std::string& path, const std::vector<unsigned char>& png,
                    const std::string& uri = "") {
  std::vector<unsigned char> bin;
  const float positions[12] = {-0.01f, -0.01f, 0, 0.01f,  -0.01f, 0,
                               0.01f,  0.01f,  0, -0.01f, 0.01f,  0};
  const float uvs[8] = {0, 0, 1, 0, 1, 1, 0, 1};
  const std::uint16_t indices[6] = {0, 1, 2, 0, 2, 3};
  append(bin, positions, sizeof(positions));
  append(bin, uvs, sizeof(uvs));
  append(bin, indices, sizeof(indices));
  const size_t image_offset = bin.size();
  append(bin, png.data(), png.size());
  while (bin.size() % 4 != 0) bin.push_back(0);
  const std::string image =
      png.empty() ? "{\"uri\":\"" + uri + "\"}" : "{\"bufferView\":3,\"mimeType\":\"image/png\"}";
  std::string json =
      "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
      "\"nodes\":[{\"mesh\":0}],"
      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},"
      "\"indices\":2,\"material\":0}]}],"
      "\"materials\":[{\"normalTexture\":{\"index\":0}}],"
      "\"textures\":[{\"source\":0}],\"images\":[" +
      image +
      "],"
      "\"buffers\":[{\"byteLength\":" +
      std::to_string(bin.size()) +
      "}],"
      "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":48},"
      "{\"buffer\":0,\"byteOffset\":48,\"byteLength\":32},"
      "{\"buffer\":0,\"byteOffset\":80,\"byteLength\":12},"
      "{\"buffer\":0,\"byteOffset\":" +
      std::to_string(image_offset) + ",\"byteLength\":" + std::to_string(png.size()) +
      "}],"
      "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\","
      "\"min\":[-0.01,-0.01,0],\"max\":[0.01,0.01,0]},"
      "{\"bufferView\":1,\"componentType\":5126,\"count\":4,\"type\":\"VEC2\"},"
      "{\"bufferView\":2,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"}]}";
  while (json.size() % 4 != 0) json += ' ';
  std::vector<unsigned char> glb;
  appendU32(glb, 0x46546C67);  // "glTF"
  appendU32(glb, 2);
  appendU32(glb, static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + bin.size()));
  appendU32(glb, static_cast<std::uint32_t>(json.size()));
  appendU32(glb, 0x4E4F534A);  // "JSON"
  append(glb, json.data(), json.size());
  appendU32(glb, static_cast<std::uint32_t>(bin.size()));
  appendU32(glb, 0x004E4942);  // "BIN"
  append(glb, bin.data(), bin.size());
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(glb.data()), static_cast<std::streamsize>(glb.size()));
}

std::vector<unsigned char> ridgesPng() {
  const AnalyticSurface s = makeRidges(cv::Size(128, 128), {0.5, 9.0, 1.5, 1.0});
  std::vector<unsigned char> png;
  cv::imencode(".png", encodeNormalMap(s.dx, s.dy, NormalConvention::kOpenGL, CV_8U), png);
  return png;
}

Eigen::Isometry3d pressed(double press_mm) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(0.0, 0.0, -press_mm * 1e-3);
  return pose;
}

TEST(ObjectTexture, EmbeddedGlbNormalTextureIsBakedAndRendersTextured) {
  test::ScratchDirectory dir;
  setenv("NORM2TEX_CACHE_DIR", dir.path("cache").c_str(), 1);  // a cold cache of its own
  const std::vector<unsigned char> png = ridgesPng();
  writeSquareGlb(dir.path("square.glb"), png);
  const auto mesh =
      std::make_shared<const TexturedMesh>(TexturedMesh::load(dir.path("square.glb")));
  EXPECT_EQ(mesh->normalTextureReference(), "*0");
  EXPECT_TRUE(mesh->normalTexturePath().empty()) << "no file of its own";
  ASSERT_EQ(mesh->embeddedNormalTexture(), png) << "the PNG's own bytes";

  const ObjectTexture texture = loadTextureFile({}, *mesh);
  ASSERT_NE(texture.atlas, nullptr) << texture.warning;
  EXPECT_TRUE(texture.warning.empty()) << texture.warning;
  EXPECT_NE(texture.description.find("normal texture *0"), std::string::npos)
      << texture.description;
  // The same texels as baking the PNG for this mesh: its chart, its scale, millimetres.
  BakeOptions physical;
  physical.physical_scale = true;
  MeshBakeReport report;
  const HeightAtlas direct = bakeHeightAtlasForMesh(
      NormalMap::fromImage(cv::imdecode(png, cv::IMREAD_UNCHANGED)), *mesh, physical, {}, &report);
  EXPECT_EQ(cv::norm(texture.atlas->heights(), direct.heights(), cv::NORM_INF), 0.0);
  EXPECT_TRUE(texture.physical_scale);
  EXPECT_EQ(texture.beta_mm, 1.0) << "heights in mm: beta is a gain";
  EXPECT_NEAR(report.mm_per_texel, 20.0 / 128.0, 1e-3) << "20 mm over 128 texels";
  // Ridges of 1 texel height on a 0.156 mm grid: the relief is about 0.16 mm.
  EXPECT_GT(report.bake.relief_amplitude_mm, 0.05);
  EXPECT_LT(report.bake.relief_amplitude_mm, 0.5);

  TactileRenderer renderer(makeDigitSensorModel());
  renderer.setObject(mesh, texture.atlas, texture.beta_mm);
  const TactileFrame textured = renderer.render(pressed(0.3), -1);
  EXPECT_TRUE(textured.textured);
  const cv::Mat3b textured_image = textured.image.clone();
  renderer.setObject(mesh, nullptr, 0.0);
  const cv::Mat3b plain = renderer.render(pressed(0.3), -1).image;
  EXPECT_GT(cv::norm(textured_image, plain, cv::NORM_L1) / plain.total(), 1.0)
      << "the texture shows in the image";

  // The next start (a new mesh load, the same file) finds the bake in the cache: the same
  // heights and island labels, nothing baked.
  const ObjectTexture again = loadTextureFile({}, TexturedMesh::load(dir.path("square.glb")));
  ASSERT_NE(again.atlas, nullptr) << again.warning;
  EXPECT_NE(again.description.find("(cached)"), std::string::npos) << again.description;
  EXPECT_EQ(cv::norm(again.atlas->heights(), texture.atlas->heights(), cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::countNonZero(again.atlas->islandLabels() != texture.atlas->islandLabels()), 0);
  EXPECT_TRUE(again.physical_scale);
  EXPECT_EQ(again.beta_mm, 1.0);
  unsetenv("NORM2TEX_CACHE_DIR");
}

TEST(ObjectTexture, MissingOrUnusableMeshTextureIsAWarningNamingIt) {
  test::ScratchDirectory dir;
  writeSquareGlb(dir.path("missing.glb"), {}, "missing_normal.png");
  const TexturedMesh missing = TexturedMesh::load(dir.path("missing.glb"));
  ObjectTexture texture = loadTextureFile({}, missing);
  EXPECT_EQ(texture.atlas, nullptr);
  EXPECT_NE(texture.warning.find("mesh's normal texture 'missing_normal.png'"), std::string::npos)
      << texture.warning;
  EXPECT_EQ(texture.warning.find('\n'), std::string::npos);

  // A truncated embedded PNG: refused, not decoded half grey.
  std::vector<unsigned char> cut = ridgesPng();
  cut.resize(cut.size() / 2);
  writeSquareGlb(dir.path("cut.glb"), cut);
  texture = loadTextureFile({}, TexturedMesh::load(dir.path("cut.glb")));
  EXPECT_EQ(texture.atlas, nullptr);
  EXPECT_NE(texture.warning.find("'*0'"), std::string::npos) << texture.warning;
  EXPECT_NE(texture.warning.find("corrupt"), std::string::npos) << texture.warning;

  // A normal map the user names is not the mesh's: its problems stay errors.
  TextureSource source;
  source.normal_map = dir.path("nope.png");
  test::expectError([&] { loadTextureFile(source, missing); }, {"nope.png"});
}

// --- ObjectTextureCache: the next texture prepared in the background --------------------------

/// A texture whose description names the key, prepared in `delay_ms`; counts preparations.
ObjectTextureCache::Prepare fakePreparation(const std::string& key, std::atomic<int>& count,
                                            int delay_ms = 0) {
  return [key, &count, delay_ms] {
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms));
    ++count;
    ObjectTexture texture;
    texture.description = key;
    texture.beta_mm = 0.1;
    return texture;
  };
}

TEST(ObjectTextureCache, PrefetchedTextureIsTheOneGetReturnsAndIsPreparedOnce) {
  ObjectTextureCache cache(2);
  std::atomic<int> count{0};
  ASSERT_TRUE(cache.prefetch("wood/1", fakePreparation("wood/1", count, 50)));
  EXPECT_FALSE(cache.prefetch("wood/1", fakePreparation("wood/1", count)));  // under way
  // A second key while the first is under way is not started (one at a time).
  EXPECT_FALSE(cache.prefetch("wood/2", fakePreparation("wood/2", count)));
  const ObjectTextureCache::Lookup first = cache.get("wood/1", fakePreparation("wrong", count));
  EXPECT_EQ(first.origin, ObjectTextureCache::Origin::kPrefetched);
  EXPECT_EQ(first.texture->description, "wood/1");
  const ObjectTextureCache::Lookup again = cache.get("wood/1", fakePreparation("wrong", count));
  EXPECT_EQ(again.origin, ObjectTextureCache::Origin::kCached);
  EXPECT_EQ(again.texture.get(), first.texture.get());
  EXPECT_EQ(count.load(), 1);
}

TEST(ObjectTextureCache, GetWithoutPrefetchPreparesOnTheCallingThread) {
  ObjectTextureCache cache(2);
  std::atomic<int> count{0};
  std::thread::id prepared_on;
  const ObjectTextureCache::Lookup lookup = cache.get("rock/0", [&] {
    prepared_on = std::this_thread::get_id();
    return fakePreparation("rock/0", count)();
  });
  EXPECT_EQ(lookup.origin, ObjectTextureCache::Origin::kPrepared);
  EXPECT_EQ(prepared_on, std::this_thread::get_id());
  EXPECT_TRUE(cache.contains("rock/0"));
}

TEST(ObjectTextureCache, BackgroundRunsWhileTheCallerGoesOn) {
  ObjectTextureCache cache(2);
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  std::thread::id prepared_on;
  ASSERT_TRUE(cache.prefetch("fabric/3", [&, released] {
    prepared_on = std::this_thread::get_id();
    released.wait();  // blocks until the test lets it finish: prefetch() must not wait for it
    ObjectTexture texture;
    texture.description = "fabric/3";
    return texture;
  }));
  EXPECT_TRUE(cache.preparing());
  EXPECT_FALSE(cache.contains("fabric/3"));
  release.set_value();
  const ObjectTextureCache::Lookup lookup = cache.get("fabric/3", [] { return ObjectTexture{}; });
  EXPECT_EQ(lookup.texture->description, "fabric/3");
  EXPECT_NE(prepared_on, std::this_thread::get_id());
  EXPECT_FALSE(cache.preparing());
}

TEST(ObjectTextureCache, BackgroundIsOneThreadThatKeepsItsScratchAcrossTextures) {
  // What a preparation leaves in thread-local scratch (TLS buffers, the malloc arena) is there
  // for the next one: they run on one long-lived thread, not a fresh one each.
  ObjectTextureCache cache(4);
  std::vector<int> earlier_on_this_thread;
  auto preparation = [&](const std::string& key) {
    return [&earlier_on_this_thread, key] {
      thread_local int prepared_here = 0;
      earlier_on_this_thread.push_back(prepared_here++);
      ObjectTexture texture;
      texture.description = key;
      return texture;
    };
  };
  for (const std::string key : {"wood/1", "wood/2", "wood/3"}) {
    ASSERT_TRUE(cache.prefetch(key, preparation(key)));
    EXPECT_EQ(cache.get(key, [] { return ObjectTexture{}; }).texture->description, key);
  }
  EXPECT_EQ(earlier_on_this_thread, (std::vector<int>{0, 1, 2}));
}

TEST(ObjectTextureCache, DestructorFinishesAPreparationItWasGiven) {
  std::atomic<int> count{0};
  {
    ObjectTextureCache cache(2);
    ASSERT_TRUE(cache.prefetch("rock/1", fakePreparation("rock/1", count, 20)));
  }
  EXPECT_EQ(count.load(), 1);
}

TEST(ObjectTextureCache, BackgroundErrorIsThrownByGetAndNotKept) {
  ObjectTextureCache cache(2);
  ASSERT_TRUE(cache.prefetch(
      "bad/0", []() -> ObjectTexture { throw Error("material 'bad': no such file"); }));
  try {
    cache.get("bad/0", [] { return ObjectTexture{}; });
    FAIL() << "expected the background's error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no such file"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(cache.contains("bad/0"));
  EXPECT_FALSE(cache.preparing());
  // Tried again on the next get(), on the calling thread.
  std::atomic<int> count{0};
  EXPECT_EQ(cache.get("bad/0", fakePreparation("bad/0", count)).origin,
            ObjectTextureCache::Origin::kPrepared);
  EXPECT_EQ(count.load(), 1);
}

TEST(ObjectTextureCache, KeepsTheMostRecentlyUsed) {
  ObjectTextureCache cache(2);
  std::atomic<int> count{0};
  cache.get("a", fakePreparation("a", count));
  cache.get("b", fakePreparation("b", count));
  cache.get("a", fakePreparation("a", count));  // a is now the most recent
  cache.get("c", fakePreparation("c", count));  // evicts b
  EXPECT_TRUE(cache.contains("a"));
  EXPECT_FALSE(cache.contains("b"));
  EXPECT_TRUE(cache.contains("c"));
  EXPECT_EQ(count.load(), 3);
  EXPECT_THROW(ObjectTextureCache(0), Error);
}

TEST(ObjectTextureCache, PrefetchOfAKeptTextureStartsNothing) {
  ObjectTextureCache cache(2);
  std::atomic<int> count{0};
  cache.get("a", fakePreparation("a", count));
  EXPECT_FALSE(cache.prefetch("a", fakePreparation("a", count)));
  EXPECT_FALSE(cache.preparing());
  // A finished background texture is taken in by the next prefetch, without any get().
  ASSERT_TRUE(cache.prefetch("b", fakePreparation("b", count)));
  while (cache.preparing()) std::this_thread::yield();
  EXPECT_FALSE(cache.prefetch("b", fakePreparation("b", count)));
  EXPECT_TRUE(cache.contains("b"));
  EXPECT_EQ(count.load(), 2);
}

TEST(ObjectTextureCache, RealMaterialPreparedInTheBackgroundEqualsOneMadeInPlace) {
  const std::string config = std::string(NORM2TEX_SOURCE_DIR) + "/config/materials/wood.yaml";
  auto mesh =
      std::make_shared<const TexturedMesh>(makeBox(Eigen::Vector3d(0.03, 0.03, 0.03), 0.02));
  const auto prepare = [&](int variant) {
    return [config, mesh, variant] {
      TextureSource source;
      source.material_config = config;
      source.variant = variant;
      TexturedMesh copy = *mesh;  // the background never touches the renderer's mesh
      return loadObjectTexture(source, copy);
    };
  };
  ObjectTextureCache cache(2);
  ASSERT_TRUE(cache.prefetch("wood/5", prepare(5)));
  const ObjectTextureCache::Lookup background = cache.get("wood/5", prepare(5));
  EXPECT_EQ(background.origin, ObjectTextureCache::Origin::kPrefetched);
  TexturedMesh copy = *mesh;
  TextureSource source;
  source.material_config = config;
  source.variant = 5;
  const ObjectTexture in_place = loadObjectTexture(source, copy);
  ASSERT_TRUE(background.texture->atlas && in_place.atlas);
  EXPECT_EQ(cv::norm(background.texture->atlas->heights(), in_place.atlas->heights(), cv::NORM_INF),
            0.0);
  EXPECT_EQ(background.texture->description, in_place.description);
}

}  // namespace
}  // namespace norm2tex

namespace norm2tex {
namespace {

// glibc's heap figures: mallinfo2 (size_t fields) arrived in glibc 2.33; Ubuntu 20.04 and
// Debian 11 have 2.31, whose mallinfo has int fields, wide enough for these tests' sizes.
struct HeapFigures {
  std::size_t mapped;        // hblkhd: bytes in blocks mapped on their own
  std::size_t free_in_heap;  // fordblks: free bytes kept in the heap
};

HeapFigures heapFigures() {
#if __GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 33)
  const auto info = mallinfo2();
#else
  const auto info = mallinfo();
#endif
  return {static_cast<std::size_t>(info.hblkhd), static_cast<std::size_t>(info.fordblks)};
}

TEST(MemoryReuse, FreedTextureSizedBlocksStayInTheHeapForTheNextOne) {
  // A 1024^2 float texture is 4 MB: by default glibc maps such a block fresh and unmaps it on
  // free, so the next texture faults every page in again.
  ASSERT_TRUE(keepFreedMemoryForReuse());
  const std::size_t size = 4u << 20;
  const std::size_t mapped_before = heapFigures().mapped;
  void* block = std::malloc(size);
  ASSERT_NE(block, nullptr);
  std::memset(block, 1, size);
  EXPECT_EQ(heapFigures().mapped, mapped_before) << "the block was mapped, not taken from the heap";
  std::free(block);
  EXPECT_GE(heapFigures().free_in_heap, size) << "the freed block went back to the kernel";
  // A 2048^2 texture's 16-bit BGRA normal map is 32 MB: at glibc's largest mmap threshold, so
  // it must not be mapped either.
  const std::size_t large = 32u << 20;
  void* big = std::malloc(large);
  ASSERT_NE(big, nullptr);
  std::memset(big, 1, large);
  EXPECT_EQ(heapFigures().mapped, mapped_before)
      << "the 32 MB block was mapped, not taken from the heap";
  std::free(big);
  EXPECT_GE(heapFigures().free_in_heap, large) << "the freed 32 MB block went back to the kernel";
}

}  // namespace
}  // namespace norm2tex

namespace norm2tex {
namespace {

long threadPageFaults() {
  rusage usage{};
  getrusage(RUSAGE_THREAD, &usage);
  return usage.ru_minflt;
}

bool transparentHugePagesOff() {
  std::ifstream file("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string modes;
  std::getline(file, modes);
  return !file || modes.find("[never]") != std::string::npos;
}

TEST(MemoryReuse, AFreedHugePageMatrixIsTheNextOneOfItsSizeAlreadyFaultedIn) {
  const auto touch = [](int rows, int cols) {
    cv::Mat1f matrix;
    createWithHugePages(matrix, rows, cols);
    matrix.setTo(1.0f);
  };
  touch(2048, 2048);  // 16 MB, freed at once
  long faults = -1;
  std::thread([&] {  // another thread, like the next variant's preparation
    const long before = threadPageFaults();
    touch(2048, 2048);
    faults = threadPageFaults() - before;
  })
      .join();
  EXPECT_LT(faults, 8) << "a fresh 16 MB mapping faults 8 huge or 4096 small pages";
}

TEST(MemoryReuse, ATexturePreparedOnAFreshThreadFaultsInFewPages) {
  // The recorder prepares each variant's texture on a new thread. A thread's heaps beyond its
  // first 64 MB are unmapped whenever they empty, so the buffers of a 2048^2 preparation
  // (~220 MB) would be faulted in again in 4 KB pages (~13 us each on our VMs) for every variant.
  if (transparentHugePagesOff()) {
    GTEST_SKIP() << "transparent huge pages are off on this machine: the texture buffers use "
                    "4 KB pages here, and this test cannot tell";
  }
  ASSERT_TRUE(keepFreedMemoryForReuse());
  const auto mesh =
      std::make_shared<const TexturedMesh>(makeBox(Eigen::Vector3d(0.03, 0.03, 0.03), 0.02));
  const auto prepare = [mesh] {
    TextureSource source;
    source.material_config = std::string(NORM2TEX_SOURCE_DIR) + "/config/materials/print3d.yaml";
    TexturedMesh copy = *mesh;
    const long before = threadPageFaults();
    const ObjectTexture texture = loadObjectTexture(source, copy);
    EXPECT_NE(texture.atlas, nullptr);
    return threadPageFaults() - before;
  };
  std::async(std::launch::async, prepare).get();  // loads what loads once
  const long faults = std::async(std::launch::async, prepare).get();
  std::printf("a 2048^2 material texture on a fresh thread: %ld page faults\n", faults);
  EXPECT_LT(faults, 3000) << "~35000 if its buffers were in 4 KB pages";
}

}  // namespace
}  // namespace norm2tex
