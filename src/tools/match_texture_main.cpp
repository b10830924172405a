// norm2tex_match_texture: fits a material's texture depth (beta_mm) to your own DIGIT's frames of
// a flat sample of it (see norm2tex/calibrate/texture_match.hpp for the method).

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "cli_arguments.hpp"
#include "norm2tex/calibrate/texture_match.hpp"
#include "norm2tex/calibrate/texture_match_report.hpp"
#include "norm2tex/calibrate/texture_sample.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/common/image_io.hpp"
#include "norm2tex/common/memory_reuse.hpp"
#include "norm2tex/materials/material_config.hpp"
#include "norm2tex/render/object_texture.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "package_paths.hpp"

namespace {

namespace fs = std::filesystem;
using norm2tex::Error;
using norm2tex::cli::UsageError;

namespace po = norm2tex::cli::po;
using norm2tex::cli::valueOr;

norm2tex::cli::Program makeProgram() {
  norm2tex::cli::Program program(
      "norm2tex_match_texture",
      "norm2tex_match_texture --background BG.png FRAME.png ... | DIR\n"
      "                              (--material NAME | --normal-map N.png --mm-per-texel S)\n"
      "                              [--forces F1,F2,... | --forces forces.csv] [--beta MM]\n"
      "                              [--sensor SENSOR.yaml] [--tilt-deg A] -o OUT.yaml\n"
      "                              [--report REPORT.png]",
      "Fits the texture depth beta_mm of a material to frames of your DIGIT pressing a flat\n"
      "sample of it (light to firm presses; tilt it slightly so part of the gel stays free).\n"
      "FRAME / DIR are the press frames (a directory: its .png/.jpg/.jpeg/.bmp/.tif/.tiff\n"
      "files, sorted by name).");
  program.positional("FRAME", -1, po::value<std::vector<std::string>>());
  program.add()  //
      ("background", po::value<std::string>()->value_name("BG.png"),
       "Your DIGIT's no-contact frame, the frames' size.")  //
      ("material", po::value<std::string>()->value_name("NAME"),
       "A material of config/materials.")  //
      ("normal-map", po::value<std::string>()->value_name("N.png"),
       "Your own texture, whose texels are --mm-per-texel mm on the surface (beta starts at "
       "--beta, default 0.1 mm).")  //
      ("mm-per-texel", po::value<double>()->value_name("S"),
       "With --normal-map: its texels' size on the surface, mm.")  //
      ("forces", po::value<std::string>()->value_name("F1,F2,...|forces.csv"),
       "Each frame's normal force (N), as a list in the frames' order or a CSV of "
       "'file,force_n' lines (file as given or its base name). Without forces each press is "
       "matched by its contact area and its force is the gel law's.")  //
      ("beta", po::value<double>()->value_name("MM"),
       "The texture depth the fit starts from (default: the material's, 0.1 mm for a normal "
       "map).")  //
      ("sensor", po::value<std::string>()->value_name("SENSOR.yaml"),
       "Your DIGIT's yaml (norm2tex_calibrate); default the package's digit.yaml.")  //
      ("tilt-deg", po::value<double>()->value_name("A"),
       "The simulated sample's tilt (default 4); its contact grows from one edge.")  //
      ("output,o", po::value<std::string>()->value_name("OUT.yaml"),
       "The material yaml with the fitted beta_mm (for --normal-map: beta_mm and the map).")  //
      ("report", po::value<std::string>()->value_name("REPORT.png"),
       "Real vs simulated crops, band spectra and band RMS against force or area.");
  return program;
}

bool isImageFile(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".tif" ||
         ext == ".tiff";
}

std::vector<std::string> framePaths(const std::vector<std::string>& arguments) {
  std::vector<std::string> paths;
  for (const std::string& argument : arguments) {
    if (!fs::is_directory(argument)) {
      paths.push_back(argument);
      continue;
    }
    std::vector<std::string> inside;
    for (const auto& entry : fs::directory_iterator(argument)) {
      if (entry.is_regular_file() && isImageFile(entry.path())) {
        inside.push_back(entry.path().string());
      }
    }
    if (inside.empty()) throw Error("frame directory '" + argument + "' holds no image files");
    std::sort(inside.begin(), inside.end());
    paths.insert(paths.end(), inside.begin(), inside.end());
  }
  return paths;
}

double parseForce(const std::string& text, const std::string& where) {
  std::istringstream in(text);
  double value = 0.0;
  if (!(in >> value) || !(in >> std::ws).eof()) {
    throw UsageError(where + ": '" + text + "' is not a number of newtons");
  }
  return value;  // finite and > 0 is checked with the frame's name (TextureMatcher)
}

// --forces as "1.5,3,8" (the frames' order) or a CSV of "file,force_n" lines.
std::vector<double> loadForces(const std::string& value, const std::vector<std::string>& frames) {
  std::vector<double> forces;
  if (!fs::is_regular_file(value)) {
    std::istringstream list(value);
    for (std::string item; std::getline(list, item, ',');) {
      forces.push_back(parseForce(item, "--forces"));
    }
  } else {
    std::ifstream in(value);
    std::map<std::string, double> by_name;
    int line_number = 0;
    for (std::string line; std::getline(in, line);) {
      ++line_number;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      if (line.find_first_not_of(" \t") == std::string::npos) continue;
      const size_t comma = line.rfind(',');
      if (comma == std::string::npos) {
        throw Error("forces '" + value + "' line " + std::to_string(line_number) +
                    ": expected 'file,force_n'");
      }
      const std::string force = line.substr(comma + 1);
      const size_t digit = force.find_first_not_of(" \t+-.");
      if (line_number == 1 &&
          (digit == std::string::npos || !std::isdigit(static_cast<unsigned char>(force[digit])))) {
        continue;  // a header line ("file,force_n")
      }
      const std::string file = line.substr(0, comma);
      const double newtons =
          parseForce(force, "forces '" + value + "' line " + std::to_string(line_number));
      // Paths from another machine still match by their base name.
      by_name[file] = newtons;
      by_name.emplace(fs::path(file).filename().string(), newtons);
    }
    for (const std::string& frame : frames) {
      auto found = by_name.find(frame);
      if (found == by_name.end()) found = by_name.find(fs::path(frame).filename().string());
      if (found == by_name.end()) {
        throw Error("forces '" + value + "' has no line for frame '" + frame + "'");
      }
      forces.push_back(found->second);
    }
  }
  if (forces.size() != frames.size()) {
    throw UsageError("--forces gives " + std::to_string(forces.size()) + " values for " +
                     std::to_string(frames.size()) + " frames; give one per frame");
  }
  return forces;
}

// The material yaml as it was, its beta_mm line replaced (comments and order kept).
void writeMaterialYaml(const std::string& source, const std::string& output,
                       const norm2tex::TextureMatchResult& result) {
  std::ifstream in(source);
  std::ostringstream text;
  char header[256];
  std::snprintf(header, sizeof(header),
                "# beta_mm fitted by norm2tex_match_texture to %zu real frames (misfit %.1f %%; "
                "was %.4g mm).\n",
                result.frames.size(), 100.0 * result.misfit, result.start_beta_mm);
  text << header << "# " << result.contact_modulus_note << "\n";
  bool replaced = false;
  for (std::string line; std::getline(in, line);) {
    if (!replaced && line.rfind("beta_mm:", 0) == 0) {
      char fitted[64];
      std::snprintf(fitted, sizeof(fitted), "beta_mm: %.4g", result.beta_mm);
      line = fitted;
      replaced = true;
    }
    text << line << "\n";
  }
  if (!replaced) {
    char fitted[64];
    std::snprintf(fitted, sizeof(fitted), "beta_mm: %.4g\n", result.beta_mm);
    text << fitted;
  }
  std::ofstream out(output);
  out << text.str();
  if (!out) throw Error("cannot write '" + output + "'");
}

void writeNormalMapYaml(const std::string& normal_map, double mm_per_texel,
                        const std::string& output, const norm2tex::TextureMatchResult& result) {
  std::ofstream out(output);
  char text[512];
  std::snprintf(text, sizeof(text),
                "# Fitted by norm2tex_match_texture to %zu real frames (misfit %.1f %%; beta was "
                "%.4g mm).\n# %s\nnormal_map: \"%s\"\nmm_per_texel: %.6g\nbeta_mm: %.4g\n",
                result.frames.size(), 100.0 * result.misfit, result.start_beta_mm,
                result.contact_modulus_note.c_str(), normal_map.c_str(), mm_per_texel,
                result.beta_mm);
  out << text;
  if (!out) throw Error("cannot write '" + output + "'");
}

int run(const norm2tex::cli::Program& program, int argc, char** argv) {
  norm2tex::keepFreedMemoryForReuse();
  const po::variables_map args = program.parse(argc, argv);
  if (!args.count("background")) throw UsageError("missing --background");
  if (!args.count("FRAME")) throw UsageError("no frames given");
  if (args.count("material") == args.count("normal-map")) {
    throw UsageError("give one of --material and --normal-map");
  }
  if (args.count("normal-map") && !args.count("mm-per-texel")) {
    throw UsageError("--normal-map needs --mm-per-texel (its texels' size on the surface, mm)");
  }
  const std::string output = valueOr<std::string>(args, "output", "");
  if (output.empty()) throw UsageError("missing -o OUT.yaml");

  const std::vector<std::string> paths = framePaths(args["FRAME"].as<std::vector<std::string>>());
  std::vector<norm2tex::TextureFrame> frames;
  for (const std::string& path : paths) {
    frames.push_back({path, norm2tex::readImage(path, cv::IMREAD_COLOR, "frame"), {}});
  }
  if (args.count("forces")) {
    const std::vector<double> values = loadForces(args["forces"].as<std::string>(), paths);
    for (size_t i = 0; i < frames.size(); ++i) frames[i].normal_force_n = values[i];
  }
  const cv::Mat3b background =
      norm2tex::readImage(args["background"].as<std::string>(), cv::IMREAD_COLOR, "background");
  const std::string sensor_path =
      valueOr(args, "sensor", norm2tex::cli::configDirectory() + "/digit.yaml");
  const norm2tex::SensorModel model = norm2tex::loadSensorModel(sensor_path);

  std::string material_path;
  norm2tex::TextureSample sample;
  const double mm_per_texel = valueOr(args, "mm-per-texel", 0.0);
  if (args.count("material")) {
    material_path = norm2tex::cli::materialConfigPath(args["material"].as<std::string>());
    sample = norm2tex::makeMaterialSample(norm2tex::loadMaterialConfig(material_path));
    sample.beta_mm = valueOr(args, "beta", sample.beta_mm);
  } else {
    sample = norm2tex::makeNormalMapSample(args["normal-map"].as<std::string>(), mm_per_texel,
                                           valueOr(args, "beta", norm2tex::kFileTextureBetaMm));
  }
  norm2tex::TextureMatchOptions options;
  options.tilt_deg = valueOr(args, "tilt-deg", options.tilt_deg);
  const norm2tex::TextureMatchResult result =
      norm2tex::TextureMatcher(model, background, sample, options).fit(frames);

  if (!material_path.empty()) {
    writeMaterialYaml(material_path, output, result);
  } else {
    writeNormalMapYaml(args["normal-map"].as<std::string>(), mm_per_texel, output, result);
  }
  if (args.count("report")) {
    norm2tex::writeImage(args["report"].as<std::string>(),
                         norm2tex::makeTextureMatchReport(result, background));
  }
  std::printf("%s: fitted on %zu frames\n", output.c_str(), frames.size());
  for (const std::string& line : norm2tex::describeTextureMatch(result)) {
    std::printf("  %s\n", line.c_str());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const norm2tex::cli::Program program = makeProgram();
  return program.main(argc, argv, [&](int argc, char** argv) { return run(program, argc, argv); });
}
