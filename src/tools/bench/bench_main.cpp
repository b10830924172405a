// norm2tex_bench: Google Benchmark executable shared by every stage of the pipeline.
// OpenCV is pinned to one thread so the figures are "one core of this machine".
#include <cstring>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>

int main(int argc, char** argv) {
  cv::setNumThreads(1);
  // Google Benchmark prints its options for --help (and exits 0) but rejects -h.
  static char help[] = "--help";
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "-h") == 0) argv[i] = help;
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
#ifdef NORM2TEX_BENCHMARK_HAS_SHUTDOWN  // Google Benchmark >= 1.5.3
  benchmark::Shutdown();
#endif
  return 0;
}
