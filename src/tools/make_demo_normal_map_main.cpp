// norm2tex_make_demo_normal_map: writes a UV-atlas-like normal map of known relief (waves,
// bumps and ridges on irregular islands, alpha = island mask) to try the bake on, until the
// procedural materials exist. The relief is analytic, so the bake can be checked by eye.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "cli_arguments.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/common/image_io.hpp"
#include "norm2tex/texture/analytic_surface.hpp"
#include "norm2tex/texture/normal_encoding.hpp"

namespace {

namespace po = norm2tex::cli::po;
using norm2tex::cli::valueOr;

norm2tex::cli::Program makeProgram() {
  norm2tex::cli::Program program(
      "norm2tex_make_demo_normal_map",
      "norm2tex_make_demo_normal_map -o OUT.png [--size PX] [--bits 8|16]\n"
      "                                     [--convention opengl|directx] [--height-out H.tiff]\n"
      "                                     [--one-island | --scan-like [--seed S]]",
      "Writes a UV-atlas-like normal map of known relief (waves, bumps and ridges on irregular\n"
      "islands, alpha = island mask) to try the bake on. The relief is analytic, so the bake\n"
      "can be checked by eye.");
  program.add()                                                                         //
      ("output,o", po::value<std::string>()->value_name("OUT.png"), "The normal map.")  //
      ("size", po::value<int>()->value_name("PX"),
       "Its width and height in texels, 64 to 8192 (default 512).")                     //
      ("bits", po::value<int>()->value_name("8|16"), "Bits per channel (default 16).")  //
      ("convention", po::value<std::string>()->value_name("opengl|directx"),
       "The green axis convention (default opengl).")  //
      ("height-out", po::value<std::string>()->value_name("H.tiff"),
       "Also the true height, 32-bit float TIFF.")  //
      ("one-island", po::bool_switch(),
       "The same relief without alpha: every texel valid, one UV island.")  //
      ("scan-like", po::bool_switch(),
       "One island of random fine relief (wavelengths 3-40 texels) whose slopes carry a weak "
       "smooth bias (hundreds of texels), as photographed or scanned normal maps do; "
       "integrated, the bias becomes long-wavelength drift.")  //
      ("seed", po::value<std::int64_t>()->value_name("S"),
       "With --scan-like: the random seed (default 1).");
  return program;
}

/// Smooth random field: white noise blurred with `sigma` texels, scaled to unit deviation.
cv::Mat1f smoothNoise(cv::Size size, double sigma, cv::RNG& rng) {
  cv::Mat1f noise(size);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 1.0);
  cv::GaussianBlur(noise, noise, cv::Size(0, 0), sigma, sigma, cv::BORDER_REFLECT);
  cv::Scalar mean, deviation;
  cv::meanStdDev(noise, mean, deviation);
  return (noise - mean[0]) / std::max(deviation[0], 1e-12);
}

/// Fine relief (octaves of smooth noise, amplitude growing with wavelength) and its exact
/// slopes, plus a smooth slope bias of 0.03 per texel, the integrator's drift source.
norm2tex::AnalyticSurface scanLikeSurface(int size, std::uint64_t seed) {
  const cv::Size extent(size, size);
  cv::RNG rng(seed);
  cv::Mat1f height(extent, 0.0f);
  for (const double sigma : {0.6, 1.2, 2.5, 5.0})
    height += 0.25 * sigma * smoothNoise(extent, sigma, rng);
  norm2tex::AnalyticSurface surface;
  surface.height = height;
  cv::Sobel(height, surface.dx, CV_32F, 1, 0, 3, 1.0 / 8.0, 0.0, cv::BORDER_REFLECT);
  cv::Sobel(height, surface.dy, CV_32F, 0, 1, 3, 1.0 / 8.0, 0.0, cv::BORDER_REFLECT);
  const double bias_sigma = size / 8.0;
  surface.dx += 0.03f * smoothNoise(extent, bias_sigma, rng);
  surface.dy += 0.03f * smoothNoise(extent, bias_sigma, rng);
  return surface;
}

int run(const norm2tex::cli::Program& program, int argc, char** argv) {
  const po::variables_map args = program.parse(argc, argv);
  const std::string output = valueOr<std::string>(args, "output", "");
  if (output.empty()) throw norm2tex::cli::UsageError("missing -o OUT.png");
  const int size = valueOr(args, "size", 512);
  const int bits = valueOr(args, "bits", 16);
  if (size < 64 || size > 8192) throw norm2tex::cli::UsageError("--size must be in [64, 8192]");
  if (bits != 8 && bits != 16) throw norm2tex::cli::UsageError("--bits must be 8 or 16");
  const bool one_island = args["one-island"].as<bool>();
  const auto convention =
      norm2tex::parseNormalConvention(valueOr<std::string>(args, "convention", "opengl"));

  if (args["scan-like"].as<bool>()) {
    const norm2tex::AnalyticSurface surface =
        scanLikeSurface(size, static_cast<std::uint64_t>(valueOr<std::int64_t>(args, "seed", 1)));
    norm2tex::writeImage(output, norm2tex::encodeNormalMap(surface.dx, surface.dy, convention,
                                                           bits == 8 ? CV_8U : CV_16U));
    if (args.count("height-out")) {
      norm2tex::writeImage(args["height-out"].as<std::string>(), surface.height);
    }
    std::printf("wrote %s (%dx%d, %d-bit RGB, %s, scan-like: one island, slope bias 0.03)\n",
                output.c_str(), size, size, bits, norm2tex::toString(convention).c_str());
    return 0;
  }

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
  norm2tex::writeImage(output, one_island ? normals : bgra);
  if (args.count("height-out")) {
    cv::Mat1f height = surface.height.clone();
    height.setTo(0.0f, islands == 0);
    norm2tex::writeImage(args["height-out"].as<std::string>(), height);
  }
  std::printf("wrote %s (%dx%d, %d-bit, %s, %s)\n", output.c_str(), size, size, bits,
              norm2tex::toString(convention).c_str(),
              one_island ? "RGB, one UV island" : "RGBA, 4 UV islands");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const norm2tex::cli::Program program = makeProgram();
  return program.main(argc, argv, [&](int argc, char** argv) { return run(program, argc, argv); });
}
