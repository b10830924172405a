// Procedural materials and UV tools, one core: BM_Texgen/<material>: a 2048^2 normal map
// (height field + 16-bit encoding); BM_MaterialVariant/<material>: one variant's whole texture
// as the probe dataset prepares it for the cube (material config, UV layout, normal map,
// bake), each iteration the next variant; BM_Unwrap_200kTriangles: an automatic atlas.
#include <benchmark/benchmark.h>

#include "norm2tex/common/memory_reuse.hpp"
#include "norm2tex/materials/material_config.hpp"
#include "norm2tex/materials/material_texture.hpp"
#include "norm2tex/mesh/mesh_primitives.hpp"
#include "norm2tex/mesh/object_mesh.hpp"
#include "package_paths.hpp"

namespace {

void BM_Texgen(benchmark::State& state, const std::string& name) {
  const auto material = norm2tex::makeMaterial(name);
  const int size = static_cast<int>(state.range(0));
  for (auto _ : state) {
    const norm2tex::MaterialTexture texture =
        norm2tex::renderMaterialTexture(*material, size, 0.05, CV_16U);
    benchmark::DoNotOptimize(texture.normal_map.data);
  }
}

void BM_MaterialVariant(benchmark::State& state, const std::string& name) {
  norm2tex::keepFreedMemoryForReuse();  // as the nodes do
  const norm2tex::MaterialConfig config =
      norm2tex::loadMaterialConfig(norm2tex::cli::materialConfigPath(name));
  const norm2tex::TexturedMesh cube = norm2tex::loadObjectMesh("box:30x30x30", 1.0).mesh;
  const int size = norm2tex::materialAtlasSize(config, cube);
  int variant = 0;
  for (auto _ : state) {
    norm2tex::TexturedMesh mesh = cube;
    const norm2tex::HeightAtlas atlas =
        norm2tex::bakeMaterialAtlas(config, 0, mesh, 4, variant++ % config.variant_count);
    benchmark::DoNotOptimize(atlas.heights().data);
  }
  state.counters["texels"] = size * size;
}

void BM_Unwrap_200kTriangles(benchmark::State& state) {
  const norm2tex::TexturedMesh with_uvs = norm2tex::makeUvSphere(0.005, 317, 317);
  const norm2tex::TexturedMesh mesh(with_uvs.vertices(), with_uvs.triangles());
  for (auto _ : state) {
    const norm2tex::UnwrapResult result = norm2tex::unwrapUvs(mesh);
    benchmark::DoNotOptimize(result.chart_count);
  }
}

BENCHMARK_CAPTURE(BM_Texgen, wood, std::string("wood"))->Arg(2048)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Texgen, fabric, std::string("fabric"))
    ->Arg(2048)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Texgen, rock, std::string("rock"))->Arg(2048)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Texgen, smooth, std::string("smooth"))
    ->Arg(2048)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Texgen, print3d, std::string("print3d"))
    ->Arg(2048)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_MaterialVariant, wood, std::string("wood"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_MaterialVariant, fabric, std::string("fabric"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_MaterialVariant, rock, std::string("rock"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_MaterialVariant, smooth, std::string("smooth"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_MaterialVariant, print3d, std::string("print3d"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Unwrap_200kTriangles)->Unit(benchmark::kMillisecond);

}  // namespace
