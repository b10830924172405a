// Procedural materials and UV tools, one core: BM_Texgen/<material>: a 2048^2 normal map
// (height field + 16-bit encoding); BM_Unwrap_200kTriangles: an automatic atlas.
#include <benchmark/benchmark.h>

#include "norm2tex/materials/material_texture.hpp"
#include "norm2tex/mesh/mesh_primitives.hpp"

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
BENCHMARK(BM_Unwrap_200kTriangles)->Unit(benchmark::kMillisecond);

}  // namespace
