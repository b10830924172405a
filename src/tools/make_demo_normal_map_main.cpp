// norm2tex_make_demo_normal_map: writes a UV-atlas-like normal map of known relief (waves,
// bumps and ridges on irregular islands, alpha = island mask) to try the bake on, until the
// procedural materials exist. The relief is analytic, so the bake can be checked by eye.
#include <cstdio>
#include <iostream>
#include <string>

#include <opencv2/core.hpp>

#include "cli_arguments.hpp"
#include "norm2tex/texture/analytic_surface.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/common/image_io.hpp"
#include "norm2tex/texture/normal_encoding.hpp"

namespace {

constexpr const char* kUsage =
    "usage: norm2tex_make_demo_normal_map -o OUT.png [--size PX] [--bits 8|16]\n"
    "                                     [--convention opengl|directx] [--height-out H.tiff]\n";

int run(int argc, char** argv) {
  const norm2tex::cli::Arguments args(
      argc, argv, {"-o", "--size", "--bits", "--convention", "--height-out"}, {"-h", "--help"});
  if (args.flag("-h") || args.flag("--help")) {
    std::cout << kUsage;
    return 0;
  }
  const std::string output = args.value("-o", "");
  if (output.empty()) throw norm2tex::cli::UsageError("missing -o OUT.png");
  const int size = args.integer("--size", 512);
  const int bits = args.integer("--bits", 16);
  if (size < 64 || size > 8192) throw norm2tex::cli::UsageError("--size must be in [64, 8192]");
  if (bits != 8 && bits != 16) throw norm2tex::cli::UsageError("--bits must be 8 or 16");
  const auto convention = norm2tex::parseNormalConvention(args.value("--convention", "opengl"));

  // Scales in fractions of the map so every size shows the same picture.
  const cv::Size extent(size, size);
  const double s = size / 512.0;
  norm2tex::AnalyticSurface surface =
      norm2tex::makeWaves(extent, {{1.2 * s, 40.0 * s, 0.3, 0.0}, {0.6 * s, 17.0 * s, 2.0, 1.0}});
  surface += norm2tex::makeBumps(extent, {{{128 * s, 128 * s}, 18 * s, 10 * s},
                                          {{384 * s, 140 * s}, 12 * s, -6 * s},
                                          {{256 * s, 400 * s}, 25 * s, 12 * s}});
  surface += norm2tex::makeRidges(extent, {0.8, 21.0 * s, 2.0 * s, 1.5 * s});
  const cv::Mat1b islands = norm2tex::makeIslandMask(extent, 2, std::max(4, size / 64));

  cv::Mat normals = norm2tex::encodeNormalMap(surface.dx, surface.dy, convention,
                                              bits == 8 ? CV_8U : CV_16U, islands);
  cv::Mat alpha;
  islands.convertTo(alpha, normals.depth(), bits == 8 ? 1.0 : 257.0);
  cv::Mat bgra;
  cv::merge(std::vector<cv::Mat>{normals, alpha}, bgra);
  norm2tex::writeImage(output, bgra);
  if (const auto height_out = args.value("--height-out")) {
    cv::Mat1f height = surface.height.clone();
    height.setTo(0.0f, islands == 0);
    norm2tex::writeImage(*height_out, height);
  }
  std::printf("wrote %s (%dx%d, %d-bit RGBA, %s, 4 UV islands)\n", output.c_str(), size, size, bits,
              norm2tex::toString(convention).c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return norm2tex::cli::runMain("norm2tex_make_demo_normal_map", kUsage, run, argc, argv);
}
