// norm2tex_export: dataset_recorder bags -> PNG frames (raw and background-subtracted), depth
// and labels.csv for training (see exportDataset).
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <iostream>

#include "cli_arguments.hpp"
#include "dataset_export.hpp"

namespace {

const char* const kUsage =
    "usage: norm2tex_export BAG [BAG ...] -o DIR [--force] [--depth png16|tiff]\n"
    "                       [--background SENSOR=FILE.png ...]\n"
    "  Writes DIR/raw/<material>/*.png, DIR/diff/<material>/*.png (image - background + 128),\n"
    "  DIR/depth/<material>/*.png (uint16 micrometres; --depth tiff: float32 metres),\n"
    "  DIR/labels.csv and DIR/export.yaml. The bags of one recording (split parts, shards) are\n"
    "  read in the order given. DIR must be empty unless --force.\n";

int run(int argc, char** argv) {
  using norm2tex::cli::UsageError;
  const norm2tex::cli::Arguments args(argc, argv, {"-o", "--out", "--depth", "--background"},
                                      {"--force"});
  norm2tex::ExportOptions options;
  options.out_dir = args.value("-o", args.value("--out", ""));
  if (options.out_dir.empty()) throw UsageError("no output directory (-o DIR)");
  if (args.positional().empty()) throw UsageError("no bag given");
  options.force = args.flag("--force");
  options.depth_format = args.value("--depth", "png16");
  if (options.depth_format != "png16" && options.depth_format != "tiff") {
    throw UsageError("--depth " + options.depth_format + " is not valid; valid: png16, tiff");
  }
  for (const std::string& spec : args.values("--background")) {
    const std::size_t eq = spec.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == spec.size()) {
      throw UsageError("--background " + spec + " is not valid; valid: SENSOR=FILE.png");
    }
    options.background_files[spec.substr(0, eq)] = spec.substr(eq + 1);
  }
  const auto start = std::chrono::steady_clock::now();
  auto seconds = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  double last_report = -1.0;
  // On a terminal the progress line rewrites itself; in a log (a pipe, a file, Slurm's output)
  // each report is a line of its own, not one enormous line of carriage returns.
  const bool terminal = isatty(fileno(stderr)) != 0;
  const norm2tex::ExportSummary summary =
      norm2tex::exportDataset(args.positional(), options, [&](std::uint64_t done) {
        const double now = seconds();
        if (now - last_report < 0.5) return;  // a progress line at most twice a second
        last_report = now;
        std::fprintf(stderr, terminal ? "\rnorm2tex_export: %lu frames (%.0f/s)"
                                      : "norm2tex_export: %lu frames (%.0f/s)\n",
                     static_cast<unsigned long>(done), done / std::max(now, 1e-9));
      });
  if (last_report >= 0.0 && terminal) std::fprintf(stderr, "\n");
  const double total = seconds();
  std::printf("norm2tex_export: %lu frames in %.2f s (%.0f frames/s) -> %s\n",
              static_cast<unsigned long>(summary.frames), total,
              summary.frames / std::max(total, 1e-9), options.out_dir.c_str());
  for (const auto& [material, n] : summary.frames_per_material) {
    std::printf("  %s: %lu\n", material.c_str(), static_cast<unsigned long>(n));
  }
  return summary.frames > 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  return norm2tex::cli::runMain("norm2tex_export", kUsage, run, argc, argv);
}
