// norm2tex_bake: normal map -> H_global (32-bit float TIFF) or an 8-bit PNG preview.
#include <algorithm>
#include <chrono>
#include <cstdio>
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

namespace po = norm2tex::cli::po;
using norm2tex::cli::valueOr;

norm2tex::cli::Program makeProgram() {
  norm2tex::cli::Program program(
      "norm2tex_bake",
      "norm2tex_bake NORMAL_MAP -o OUT.(tiff|tif|png) [--mask M] [--convention opengl|directx]\n"
      "                     [--range 0,-1|-1,1|0,1] [--alpha A] [--sigma-fine S] [--sigma-coarse "
      "S]\n"
      "                     [--percentile-low P] [--percentile-high P] [--boundary "
      "neumann|periodic]\n"
      "                     [--tolerance T] [--max-iterations N]\n"
      "                     [--relief-cutoff-texels N | --relief-cutoff-mm MM] [--mm-per-texel "
      "MM]\n"
      "                     [--physical] [--paper-exact] [--mesh M [--scale S]] [--quiet]",
      "Bakes a UV normal map into H_global, the global pseudo-height map of the texture\n"
      "(Frankot-Chellappa per UV island, fine and coarse passes, percentile normalisation). An\n"
      "OUT ending in .tiff or .tif gets H_global as single-channel 32-bit float (invalid texels\n"
      "NaN); one ending in .png an 8-bit preview, the range's low end black and its high end\n"
      "white. The defaults are the paper's, plus mean-slope removal and a relief high-pass:\n"
      "wavelengths above 64 texels (2 mm with --mm-per-texel) are drift, not relief.");
  program.positional("NORMAL_MAP", 1, po::value<std::string>());
  program.add()  //
      ("output,o", po::value<std::string>()->value_name("OUT"),
       "The output file: .tiff or .tif (H_global, float), .png (preview).")  //
      ("mask", po::value<std::string>()->value_name("M"),
       "An image whose non-zero texels are the valid ones (default: the map's alpha).")  //
      ("convention", po::value<std::string>()->value_name("opengl|directx"),
       "The normal map's green axis convention (default opengl).")  //
      ("range", po::value<std::string>()->value_name("0,-1|-1,1|0,1"),
       "The height range H_global is normalised to (default -1,1).")  //
      ("alpha", po::value<double>()->value_name("A"),
       "H = (1 - A) H_fine + A H_coarse, in [0, 1] (default 0.2).")  //
      ("sigma-fine", po::value<double>()->value_name("S"),
       "Texels; the fine pass's Gaussian on the normals (default 0.35).")  //
      ("sigma-coarse", po::value<double>()->value_name("S"),
       "Texels; the coarse pass's Gaussian (default 1.1).")  //
      ("percentile-low", po::value<double>()->value_name("P"),
       "Percent; maps to the range's low end, outliers clipped (default 0.05).")  //
      ("percentile-high", po::value<double>()->value_name("P"),
       "Percent; maps to the range's high end (default 99.95).")  //
      ("boundary", po::value<std::string>()->value_name("neumann|periodic"),
       "The Poisson solve's boundary (default neumann; periodic with --paper-exact).")  //
      ("tolerance", po::value<double>()->value_name("T"),
       "The iterative solve's relative residual to reach (default 1e-4).")  //
      ("max-iterations", po::value<int>()->value_name("N"),
       "The iterative solve's iterations at most (default 300).")  //
      ("relief-cutoff-texels", po::value<double>()->value_name("N"),
       "The relief high-pass: longer wavelengths are drift (default 64; 0 keeps all).")  //
      ("relief-cutoff-mm", po::value<double>()->value_name("MM"),
       "The relief high-pass in mm of surface (default 2; needs --mm-per-texel).")  //
      ("mm-per-texel", po::value<double>()->value_name("MM"),
       "Millimetres of surface per texel; with --physical H_global is in mm (the relief the "
       "normal map implies) and beta becomes a gain.")                                     //
      ("physical", po::bool_switch(), "H_global in mm (needs --mm-per-texel or --mesh).")  //
      ("paper-exact", po::bool_switch(),
       "The paper's bake only: no high-pass, no mean-slope removal, periodic boundary.")  //
      ("mesh", po::value<std::string>()->value_name("M"),
       "The texture's mesh: its UV charts are the islands (texels outside every chart invalid), "
       "its UV scale gives mm per texel, and islands get offsets that make heights agree across "
       "the mesh's seams.")  //
      ("scale", po::value<double>()->value_name("S"),
       "The mesh's units to metres (default 1; 0.001 for a mesh in mm).")  //
      ("quiet", po::bool_switch(), "Print nothing but errors and warnings.");
  return program;
}

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

norm2tex::BakeOptions parseOptions(const po::variables_map& args) {
  norm2tex::BakeOptions options =
      args["paper-exact"].as<bool>() ? norm2tex::paperExactBakeOptions() : norm2tex::BakeOptions();
  options.normal_map.convention =
      norm2tex::parseNormalConvention(valueOr<std::string>(args, "convention", "opengl"));
  options.range = norm2tex::parseHeightRange(valueOr<std::string>(args, "range", "-1,1"));
  options.alpha = valueOr(args, "alpha", options.alpha);
  options.sigma_fine = valueOr(args, "sigma-fine", options.sigma_fine);
  options.sigma_coarse = valueOr(args, "sigma-coarse", options.sigma_coarse);
  options.percentile_low = valueOr(args, "percentile-low", options.percentile_low);
  options.percentile_high = valueOr(args, "percentile-high", options.percentile_high);
  options.integration.tolerance = valueOr(args, "tolerance", options.integration.tolerance);
  options.integration.max_iterations =
      valueOr(args, "max-iterations", options.integration.max_iterations);
  options.relief_cutoff_texels =
      valueOr(args, "relief-cutoff-texels", options.relief_cutoff_texels);
  options.relief_cutoff_mm = valueOr(args, "relief-cutoff-mm", options.relief_cutoff_mm);
  options.mm_per_texel = valueOr(args, "mm-per-texel", options.mm_per_texel);
  options.physical_scale = args["physical"].as<bool>();
  if (args.count("relief-cutoff-mm") && !args.count("mm-per-texel")) {
    throw norm2tex::cli::UsageError("--relief-cutoff-mm needs --mm-per-texel");
  }
  const std::string default_boundary =
      options.integration.boundary == norm2tex::PoissonBoundary::kPeriodic ? "periodic" : "neumann";
  const std::string boundary = valueOr(args, "boundary", default_boundary);
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
  if (args.count("mesh") && checked.mm_per_texel == 0.0) checked.physical_scale = false;
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

int run(const norm2tex::cli::Program& program, int argc, char** argv) {
  // Every large matrix of this short-lived process (the decoded PNG included) on huge pages.
  cv::Mat::setDefaultAllocator(norm2tex::hugePageAllocator());
  const po::variables_map args = program.parse(argc, argv);
  if (!args.count("NORMAL_MAP")) throw norm2tex::cli::UsageError("missing NORMAL_MAP");
  const std::string input = args["NORMAL_MAP"].as<std::string>();
  const std::string output = valueOr<std::string>(args, "output", "");
  if (output.empty()) throw norm2tex::cli::UsageError("missing -o OUT");
  const std::string extension = norm2tex::lowerCaseExtension(output);
  if (extension != ".tiff" && extension != ".tif" && extension != ".png") {
    throw norm2tex::cli::UsageError("OUT must end in .tiff, .tif or .png, got '" + output + "'");
  }
  const bool quiet = args["quiet"].as<bool>();
  const norm2tex::BakeOptions options = parseOptions(args);

  const auto start = Clock::now();
  const norm2tex::NormalMap normal_map = [&] {
    const norm2tex::cli::QuietStderr quiet_decoders;
    return norm2tex::NormalMap::load(input, options.normal_map,
                                     valueOr<std::string>(args, "mask", ""));
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
  if (args.count("mesh")) {
    // The mesh's UV charts are the islands, its scale sets mm per texel, seams are matched.
    norm2tex::MeshLoadOptions mesh_options;
    mesh_options.scale = valueOr(args, "scale", 1.0);
    const norm2tex::TexturedMesh mesh =
        norm2tex::TexturedMesh::load(args["mesh"].as<std::string>(), mesh_options);
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
    std::printf("%s: %dx%d texels, %d valid, %d UV island%s\n", input.c_str(), normal_map.cols(),
                normal_map.rows(), report.valid_texels, report.island_count,
                report.island_count == 1 ? "" : "s");
    if (report.relief_cutoff_texels > 0.0) {
      std::printf("relief high-pass at %.4g texels; ", report.relief_cutoff_texels);
    } else {
      std::printf("no relief high-pass; ");
    }
    std::printf("%.0f %% of H_global's variance at wavelengths above 64 texels\n",
                100.0 * long_wavelength_fraction);
    if (args.count("mesh")) {
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
  const norm2tex::cli::Program program = makeProgram();
  return program.main(argc, argv, [&](int argc, char** argv) { return run(program, argc, argv); });
}
