// norm2tex_bake: normal map -> H_global (32-bit float TIFF) or an 8-bit PNG preview.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <limits>
#include <string>

#include <opencv2/core.hpp>

#include "cli_arguments.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/common/huge_pages.hpp"
#include "norm2tex/common/image_io.hpp"
#include "norm2tex/mesh/textured_mesh.hpp"
#include "norm2tex/texture/height_atlas_baker.hpp"
#include "norm2tex/texture/mesh_bake.hpp"
#include "norm2tex/texture/relief_spectrum.hpp"
#include "quiet_stderr.hpp"

namespace {

constexpr const char* kUsage =
    "usage: norm2tex_bake NORMAL_MAP -o OUT.(tiff|tif|png) [--mask M] [--convention "
    "opengl|directx]\n"
    "                     [--range 0,-1|-1,1|0,1] [--alpha A] [--sigma-fine S] [--sigma-coarse S]\n"
    "                     [--percentile-low P] [--percentile-high P] [--boundary "
    "neumann|periodic]\n"
    "                     [--tolerance T] [--max-iterations N]\n"
    "                     [--relief-cutoff-texels N | --relief-cutoff-mm MM] [--mm-per-texel MM]\n"
    "                     [--physical] [--paper-exact] [--mesh M [--scale S]] [--quiet]\n"
    "  OUT.tiff/.tif: H_global as single-channel 32-bit float (invalid texels NaN)\n"
    "  OUT.png:       8-bit preview, the range's low end black and high end white\n"
    "  Defaults are the paper's: convention opengl, range -1,1, alpha 0.2, sigma-fine 0.35,\n"
    "  sigma-coarse 1.1, percentiles 0.05 / 99.95; plus mean-slope removal and a relief\n"
    "  high-pass: wavelengths above 64 texels (2 mm with --mm-per-texel) are drift, not relief\n"
    "  (0 = keep all).\n"
    "  --mm-per-texel: millimetres of surface per texel; with --physical H_global is in mm\n"
    "                  (the relief the normal map implies) and beta becomes a gain.\n"
    "  --paper-exact:  the paper's bake only (no high-pass, no mean-slope removal, periodic).\n"
    "  --mesh M [--scale S]: the texture's mesh: its UV charts are the islands (texels outside\n"
    "                  every chart invalid), its UV scale gives mm per texel, and islands get\n"
    "                  offsets that make heights agree across the mesh's seams.\n";

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

norm2tex::BakeOptions parseOptions(const norm2tex::cli::Arguments& args) {
  norm2tex::BakeOptions options =
      args.flag("--paper-exact") ? norm2tex::paperExactBakeOptions() : norm2tex::BakeOptions();
  options.normal_map.convention =
      norm2tex::parseNormalConvention(args.value("--convention", "opengl"));
  options.range = norm2tex::parseHeightRange(args.value("--range", "-1,1"));
  options.alpha = args.number("--alpha", options.alpha);
  options.sigma_fine = args.number("--sigma-fine", options.sigma_fine);
  options.sigma_coarse = args.number("--sigma-coarse", options.sigma_coarse);
  options.percentile_low = args.number("--percentile-low", options.percentile_low);
  options.percentile_high = args.number("--percentile-high", options.percentile_high);
  options.integration.tolerance = args.number("--tolerance", options.integration.tolerance);
  options.integration.max_iterations =
      args.integer("--max-iterations", options.integration.max_iterations);
  options.relief_cutoff_texels =
      args.number("--relief-cutoff-texels", options.relief_cutoff_texels);
  options.relief_cutoff_mm = args.number("--relief-cutoff-mm", options.relief_cutoff_mm);
  options.mm_per_texel = args.number("--mm-per-texel", options.mm_per_texel);
  options.physical_scale = args.flag("--physical");
  if (args.has("--relief-cutoff-mm") && !args.has("--mm-per-texel")) {
    throw norm2tex::cli::UsageError("--relief-cutoff-mm needs --mm-per-texel");
  }
  const std::string default_boundary =
      options.integration.boundary == norm2tex::PoissonBoundary::kPeriodic ? "periodic" : "neumann";
  const std::string boundary = args.value("--boundary", default_boundary);
  // "mirror" is the old name of the cosine-transform (Neumann) solve.
  if (boundary == "neumann" || boundary == "mirror") {
    options.integration.boundary = norm2tex::PoissonBoundary::kNeumann;
  } else if (boundary == "periodic") {
    options.integration.boundary = norm2tex::PoissonBoundary::kPeriodic;
  } else {
    throw norm2tex::Error("unknown --boundary '" + boundary + "'; valid: neumann, periodic");
  }
  // With --mesh, mm per texel comes from the mesh (checked when it is known).
  norm2tex::BakeOptions checked = options;
  if (args.has("--mesh") && checked.mm_per_texel == 0.0) checked.physical_scale = false;
  norm2tex::validate(checked);
  return options;
}

/// The range's low end maps to 0, its high end to 255 (with --physical: the lowest and highest
/// valid height); invalid texels are 0.
cv::Mat previewImage(const norm2tex::HeightAtlas& atlas, const norm2tex::BakeOptions& options) {
  cv::Vec2f bounds = norm2tex::rangeBounds(options.range);
  if (options.physical_scale) {
    double low = 0.0, high = 0.0;
    cv::minMaxLoc(atlas.heights(), &low, &high, nullptr, nullptr, atlas.valid());
    bounds = cv::Vec2f(static_cast<float>(low), static_cast<float>(std::max(high, low + 1e-9)));
  }
  cv::Mat preview;
  atlas.heights().convertTo(preview, CV_8U, 255.0 / (bounds[1] - bounds[0]),
                            -255.0 * bounds[0] / (bounds[1] - bounds[0]));
  preview.setTo(0, atlas.valid() == 0);
  return preview;
}

int run(int argc, char** argv) {
  // Every large matrix of this short-lived process (the decoded PNG included) on huge pages.
  cv::Mat::setDefaultAllocator(norm2tex::hugePageAllocator());
  const norm2tex::cli::Arguments args(
      argc, argv,
      {"-o", "--output", "--mask", "--convention", "--range", "--alpha", "--sigma-fine",
       "--sigma-coarse", "--percentile-low", "--percentile-high", "--boundary", "--tolerance",
       "--max-iterations", "--relief-cutoff-texels", "--relief-cutoff-mm", "--mm-per-texel",
       "--mesh", "--scale"},
      {"--quiet", "-h", "--help", "--physical", "--paper-exact"});
  if (args.flag("-h") || args.flag("--help")) {
    std::cout << kUsage;
    return 0;
  }
  if (args.positional().size() != 1) {
    throw norm2tex::cli::UsageError("expected exactly one NORMAL_MAP argument");
  }
  const std::string output = args.value("-o", args.value("--output", ""));
  if (output.empty()) throw norm2tex::cli::UsageError("missing -o OUT");
  const std::string extension = norm2tex::lowerCaseExtension(output);
  if (extension != ".tiff" && extension != ".tif" && extension != ".png") {
    throw norm2tex::cli::UsageError("OUT must end in .tiff, .tif or .png, got '" + output + "'");
  }
  const bool quiet = args.flag("--quiet");
  const norm2tex::BakeOptions options = parseOptions(args);

  const auto start = Clock::now();
  const norm2tex::NormalMap normal_map = [&] {
    const norm2tex::cli::QuietStderr quiet_decoders;
    return norm2tex::NormalMap::load(args.positional()[0], options.normal_map,
                                     args.value("--mask", ""));
  }();
  const double load_seconds = secondsSince(start);

  // Progress only where a bake takes long enough to wonder (about 1 Mtexel and up).
  const bool show_progress = !quiet && normal_map.rows() * normal_map.cols() >= 1024 * 1024;
  int last_percent = -1;
  const auto progress = [&](double fraction) {
    const int percent = static_cast<int>(fraction * 100.0);
    if (percent / 5 == last_percent / 5) return;
    last_percent = percent;
    std::fprintf(stderr, "\rbaking: %3d%%", percent);
    if (percent >= 100) std::fprintf(stderr, "\n");
    std::fflush(stderr);
  };

  const auto bake_start = Clock::now();
  norm2tex::BakeReport report;
  norm2tex::MeshBakeReport mesh_report;
  const norm2tex::BakeProgress shown = show_progress ? norm2tex::BakeProgress(progress) : nullptr;
  norm2tex::HeightAtlas atlas;
  if (const auto mesh_path = args.value("--mesh")) {
    // The mesh's UV charts are the islands, its scale sets mm per texel, seams are matched.
    norm2tex::MeshLoadOptions mesh_options;
    mesh_options.scale = args.number("--scale", 1.0);
    const norm2tex::TexturedMesh mesh = norm2tex::TexturedMesh::load(*mesh_path, mesh_options);
    atlas = norm2tex::bakeHeightAtlasForMesh(normal_map, mesh, options, shown, &mesh_report);
    report = mesh_report.bake;
  } else {
    atlas = norm2tex::bakeHeightAtlas(normal_map, options, shown, &report);
  }
  const double bake_seconds = secondsSince(bake_start);
  const double long_wavelength_fraction =
      quiet ? 0.0 : norm2tex::longWavelengthVarianceFraction(atlas.heights(), atlas.valid(), 64.0);
  if (extension == ".png") {
    norm2tex::writeImage(output, previewImage(atlas, options));
  } else {
    // Invalid texels are NaN in the TIFF: --atlas reads them back as invalid, so the file
    // keeps the atlas's validity mask (0 would be a valid height of 0).
    norm2tex::writeImage(output, std::move(atlas).takeHeightsInvalidAsNaN());
  }
  if (!quiet) {
    std::printf("%s: %dx%d texels, %d valid, %d UV island%s\n", args.positional()[0].c_str(),
                normal_map.cols(), normal_map.rows(), report.valid_texels, report.island_count,
                report.island_count == 1 ? "" : "s");
    if (report.relief_cutoff_texels > 0.0) {
      std::printf("relief high-pass at %.4g texels; ", report.relief_cutoff_texels);
    } else {
      std::printf("no relief high-pass; ");
    }
    std::printf("%.0f %% of H_global's variance at wavelengths above 64 texels\n",
                100.0 * long_wavelength_fraction);
    if (args.has("--mesh")) {
      std::printf(
          "mesh: %d UV charts, %.4g mm per texel; %d seam edges, step across seams %.1f%% -> "
          "%.1f%% of the relief amplitude after island offsets\n",
          mesh_report.chart_count, mesh_report.mm_per_texel, mesh_report.seams.seam_edges,
          100.0 * mesh_report.seams.step_before, 100.0 * mesh_report.seams.step_after);
    }
    if (options.mm_per_texel > 0.0 || mesh_report.mm_per_texel > 0.0) {
      std::printf("implied relief amplitude %.4g mm (percentiles %.2f..%.2f at %.4g mm/texel)%s\n",
                  report.relief_amplitude_mm, options.percentile_low, options.percentile_high,
                  options.mm_per_texel > 0.0 ? options.mm_per_texel : mesh_report.mm_per_texel,
                  options.physical_scale ? "; H_global in mm, use beta as a gain (1)" : "");
    }
    if (report.unconverged_islands > 0) {
      std::fprintf(stderr,
                   "norm2tex_bake: warning: %d island(s) stopped at --max-iterations %d with "
                   "relative residual %.2g (tolerance %.2g)\n",
                   report.unconverged_islands, options.integration.max_iterations,
                   report.worst_relative_residual, options.integration.tolerance);
    }
    std::printf("range %s, percentiles %.2f/%.2f at %.6g/%.6g\n",
                norm2tex::toString(options.range).c_str(), options.percentile_low,
                options.percentile_high, report.percentile_values[0], report.percentile_values[1]);
    std::printf("load %.3f s, bake %.3f s, total %.3f s -> %s\n", load_seconds, bake_seconds,
                secondsSince(start), output.c_str());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return norm2tex::cli::runMain("norm2tex_bake", kUsage, run, argc, argv);
}
