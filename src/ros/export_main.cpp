// norm2tex_export: dataset_recorder bags -> PNG frames (raw and background-subtracted), depth
// and labels.csv for training (see exportDataset).
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "cli_arguments.hpp"
#include "dataset_export.hpp"

namespace {

namespace po = norm2tex::cli::po;
using norm2tex::cli::UsageError;

norm2tex::cli::Program makeProgram() {
  norm2tex::cli::Program program(
      "norm2tex_export",
      "norm2tex_export BAG [BAG ...] -o DIR [--force] [--depth png16|tiff]\n"
      "                       [--background SENSOR=FILE.png ...]",
      "Exports dataset_recorder bags for training: DIR/raw/<material>/*.png,\n"
      "DIR/diff/<material>/*.png (image - background + 128), DIR/depth/<material>/*.png\n"
      "(uint16 micrometres; --depth tiff: float32 metres), DIR/markers/<material>/*.csv (sensors\n"
      "with markers), DIR/shear/<material>/*.npy (recorded with ~record_shear), DIR/labels.csv\n"
      "and DIR/export.yaml.\n"
      "The bags of one recording (split parts, shards) are read in the order given.");
  program.positional("BAG", -1, po::value<std::vector<std::string>>());
  program.add()  //
      ("output,out,o", po::value<std::string>()->value_name("DIR"),
       "The output directory (also --out); it must be empty unless --force.")  //
      ("force", po::bool_switch(), "Write into a DIR that is not empty.")      //
      ("depth", po::value<std::string>()->value_name("png16|tiff"),
       "The depth images' format (default png16).")  //
      ("background",
       po::value<std::vector<std::string>>()->composing()->value_name("SENSOR=FILE.png"),
       "A sensor's background for the diff images when the bags hold none (the renderer's "
       "latched SENSOR/background), repeatable.");
  return program;
}

int run(const norm2tex::cli::Program& program, int argc, char** argv) {
  const po::variables_map args = program.parse(argc, argv);
  norm2tex::ExportOptions options;
  options.out_dir = norm2tex::cli::valueOr<std::string>(args, "output", "");
  if (options.out_dir.empty()) throw UsageError("no output directory (-o DIR)");
  if (!args.count("BAG")) throw UsageError("no bag given");
  const std::vector<std::string> bags = args["BAG"].as<std::vector<std::string>>();
  options.force = args["force"].as<bool>();
  options.depth_format = norm2tex::cli::valueOr<std::string>(args, "depth", "png16");
  if (options.depth_format != "png16" && options.depth_format != "tiff") {
    throw UsageError("--depth " + options.depth_format + " is not valid; valid: png16, tiff");
  }
  for (const std::string& spec :
       norm2tex::cli::valueOr(args, "background", std::vector<std::string>())) {
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
      norm2tex::exportDataset(bags, options, [&](std::uint64_t done) {
        const double now = seconds();
        if (now - last_report < 0.5) return;  // a progress line at most twice a second
        last_report = now;
        std::fprintf(stderr,
                     terminal ? "\rnorm2tex_export: %lu frames (%.0f/s)"
                              : "norm2tex_export: %lu frames (%.0f/s)\n",
                     static_cast<unsigned long>(done), done / std::max(now, 1e-9));
      });
  if (last_report >= 0.0 && terminal) std::fprintf(stderr, "\n");
  for (const std::string& warning : summary.warnings) {
    std::fprintf(stderr, "norm2tex_export: warning: %s\n", warning.c_str());
  }
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
  const norm2tex::cli::Program program = makeProgram();
  return program.main(argc, argv, [&](int argc, char** argv) { return run(program, argc, argv); });
}
