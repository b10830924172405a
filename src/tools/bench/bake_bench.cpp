// BM_Bake/<size>/islands:<n>: normal map -> H_global, default options, one core, warm (a
// running process; cold figures, a fresh process per bake, come from scripts/bake_timing).
#include <benchmark/benchmark.h>

#include "norm2tex/texture/analytic_surface.hpp"
#include "norm2tex/texture/height_atlas_baker.hpp"
#include "norm2tex/texture/normal_encoding.hpp"

namespace {

norm2tex::NormalMap makeNormalMap(int size, int cells_per_side) {
  const cv::Size extent(size, size);
  norm2tex::AnalyticSurface surface =
      norm2tex::makeWaves(extent, {{1.0, size / 9.0, 0.4, 0.0}, {0.5, 13.0, 1.9, 0.5}});
  surface += norm2tex::makeRidges(extent, {0.7, 19.0, 2.0, 1.0});
  const cv::Mat1b mask = cells_per_side == 1 ? cv::Mat1b(extent, uchar(255))
                                             : norm2tex::makeIslandMask(extent, cells_per_side, 4);
  const cv::Mat image = norm2tex::encodeNormalMap(
      surface.dx, surface.dy, norm2tex::NormalConvention::kOpenGL, CV_16U, mask);
  return norm2tex::NormalMap::fromImage(image, {}, mask);
}

void BM_Bake(benchmark::State& state) {
  const int size = static_cast<int>(state.range(0));
  const int islands = static_cast<int>(state.range(1));
  const int cells = islands == 1 ? 1 : static_cast<int>(std::lround(std::sqrt(islands)));
  const norm2tex::NormalMap normal_map = makeNormalMap(size, cells);
  norm2tex::BakeReport report;
  for (auto _ : state) {
    norm2tex::HeightAtlas atlas = norm2tex::bakeHeightAtlas(normal_map, {}, {}, &report);
    benchmark::DoNotOptimize(atlas.heights().data);
  }
  state.counters["islands"] = report.island_count;
  state.counters["solves"] = report.poisson_solves;  // cosine-transform solves, all islands
  state.counters["Mtexel/s"] = benchmark::Counter(static_cast<double>(size) * size * 1e-6,
                                                  benchmark::Counter::kIsIterationInvariantRate);
}

// One island filling the map, and a 16 x 16 atlas of irregular islands (rectangles, discs,
// triangles) with 4-texel gaps, the shape of a real UV unwrap.
BENCHMARK(BM_Bake)
    ->ArgNames({"", "islands"})
    ->ArgsProduct({{512, 1024, 2048, 4096}, {1, 256}})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.5)
    ->UseRealTime();

}  // namespace
