// norm2tex_texgen: procedural material -> normal map (+ albedo, height, UV-unwrapped mesh),
// material variants, and the gallery of every material through the tactile renderer
// (docs/materials.md).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "cli_arguments.hpp"
#include "contact_sheet.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/common/image_io.hpp"
#include "norm2tex/materials/material_config.hpp"
#include "norm2tex/materials/material_texture.hpp"
#include "norm2tex/mesh/mesh_primitives.hpp"
#include "norm2tex/render/tactile_renderer.hpp"
#include "norm2tex/texture/height_atlas_baker.hpp"
#include "package_paths.hpp"
#include "quiet_stderr.hpp"

namespace {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace po = norm2tex::cli::po;
using norm2tex::cli::valueOr;

norm2tex::cli::Program makeProgram() {
  norm2tex::cli::Program program(
      "norm2tex_texgen",
      "norm2tex_texgen --material NAME [--config M.yaml] [--param key=value ...] [--seed S]\n"
      "                       [--size PX | --mm-per-texel R] [--bits 8|16] [--mesh IN [--scale "
      "S]]\n"
      "                       [--out-mesh OUT.obj] [--padding PX] -o NORMAL.png [--albedo A.png]\n"
      "                       [--height-out H.tiff]\n"
      "       norm2tex_texgen --material NAME --variants K --out-dir DIR [--seed S] [...]\n"
      "       norm2tex_texgen --list\n"
      "       norm2tex_texgen --gallery -o GALLERY.png [--seed S]",
      "Generates a procedural material's normal map (and its albedo, height and, for a mesh\n"
      "without UVs, the UV-unwrapped mesh), variants of it, or the gallery of every material\n"
      "through the tactile renderer. NAME is wood, fabric, rock, smooth or print3d; its defaults\n"
      "(parameters, beta, range, texture size and mm per texel) come from\n"
      "config/materials/NAME.yaml.");
  program.add()                                                                    //
      ("material", po::value<std::string>()->value_name("NAME"), "The material.")  //
      ("config", po::value<std::string>()->value_name("M.yaml"),
       "A material yaml instead of config/materials/NAME.yaml.")  //
      ("param", po::value<std::vector<std::string>>()->composing()->value_name("key=value"),
       "Overrides one parameter; repeatable (see --list for names, units and ranges).")     //
      ("seed", po::value<std::int64_t>()->value_name("S"), "The random seed (default 1).")  //
      ("size", po::value<int>()->value_name("PX"),
       "The texture's size in texels (default: the material's).")  //
      ("mm-per-texel", po::value<double>()->value_name("R"),
       "Millimetres of surface per texel (default: the material's).")                        //
      ("bits", po::value<int>()->value_name("8|16"), "The normal map's bits (default 16).")  //
      ("mesh", po::value<std::string>()->value_name("IN"),
       "A texture for that mesh. With UVs, every UV island gets the relief at its own "
       "millimetre scale, in the atlas the nodes use (the smallest of size, size/2, ... whose "
       "texels are at most mm per texel on the mesh; --size forces a size); without, the mesh "
       "is unwrapped into a new atlas of size texels and written to --out-mesh with a material "
       "that references NORMAL.png.")  //
      ("scale", po::value<double>()->value_name("S"),
       "The mesh's units to metres (default 1; 0.001 for a mesh in mm).")  //
      ("out-mesh", po::value<std::string>()->value_name("OUT.obj"),
       "Where the unwrapped mesh goes (default: NORMAL_mesh.obj).")  //
      ("padding", po::value<int>()->value_name("PX"),
       "Texels of padding around each UV island (default 4).")  //
      ("output,o", po::value<std::string>()->value_name("NORMAL.png"),
       "The normal map (with --gallery: the gallery).")                              //
      ("albedo", po::value<std::string>()->value_name("A.png"), "Also the albedo.")  //
      ("height-out", po::value<std::string>()->value_name("H.tiff"),
       "Also the height, mm, 32-bit float TIFF.")  //
      ("variants", po::value<int>()->value_name("K"),
       "K variants (1 to 1000) drawn from the config's variant ranges, NAME_NN_normal.png and "
       "NAME_NN_albedo.png in --out-dir with variants.yaml listing their parameters.")  //
      ("out-dir", po::value<std::string>()->value_name("DIR"), "Where --variants go.")  //
      ("list", po::bool_switch(), "List the materials and their parameters.")           //
      ("gallery", po::bool_switch(),
       "Every material through the tactile renderer: albedo, normal map, no texture, texture.");
  return program;
}

norm2tex::MaterialConfig loadConfig(const po::variables_map& args, const std::string& material) {
  const std::string path = args.count("config") ? args["config"].as<std::string>()
                                                : norm2tex::cli::materialConfigPath(material);
  norm2tex::MaterialConfig config = norm2tex::loadMaterialConfig(path);
  for (const std::string& assignment : valueOr(args, "param", std::vector<std::string>())) {
    const size_t equals = assignment.find('=');
    if (equals == std::string::npos) {
      throw norm2tex::cli::UsageError("--param expects key=value, got '" + assignment + "'");
    }
    char* end = nullptr;
    const std::string text = assignment.substr(equals + 1);
    const double value = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0' || !std::isfinite(value)) {
      throw norm2tex::cli::UsageError("--param " + assignment.substr(0, equals) +
                                      " expects a number, got '" + text + "'");
    }
    config.parameters[assignment.substr(0, equals)] = value;
    config.variant_ranges.erase(assignment.substr(0, equals));  // pinned in every variant too
  }
  return config;
}

void listMaterials() {
  for (const std::string& name : norm2tex::materialNames()) {
    const auto material = norm2tex::makeMaterial(name);
    std::printf("%s\n", name.c_str());
    for (const norm2tex::MaterialParameter& p : material->parameters()) {
      std::printf("  %-24s %10.4g  [%g, %g] %-4s %s\n", p.name.c_str(), p.value, p.min, p.max,
                  p.unit.c_str(), p.description.c_str());
    }
  }
}

void writeVariantsManifest(
    const std::string& path, const norm2tex::MaterialConfig& config,
    const std::vector<std::unique_ptr<norm2tex::ProceduralMaterial>>& variants,
    std::uint64_t seed) {
  std::ofstream out(path);
  out << "material: " << config.name << "\nseed: " << seed << "\nvariants:\n";
  for (size_t k = 0; k < variants.size(); ++k) {
    out << "  - index: " << k + 1 << "\n    parameters:\n";
    for (const norm2tex::MaterialParameter& p : variants[k]->parameters()) {
      out << "      " << p.name << ": " << p.value << "\n";
    }
  }
  if (!out) throw norm2tex::Error("cannot write '" + path + "'");
}

int writeVariants(const po::variables_map& args, const norm2tex::MaterialConfig& config,
                  std::uint64_t seed, int size, double mm_per_texel, int depth) {
  const int count = args["variants"].as<int>();
  if (count < 1 || count > 1000) throw norm2tex::cli::UsageError("--variants must be in [1, 1000]");
  const std::string dir = valueOr<std::string>(args, "out-dir", "");
  if (dir.empty()) throw norm2tex::cli::UsageError("--variants needs --out-dir DIR");
  fs::create_directories(dir);
  std::vector<std::unique_ptr<norm2tex::ProceduralMaterial>> variants;
  for (int k = 1; k <= count; ++k) {
    variants.push_back(norm2tex::makeMaterialVariant(config, k, seed));
    const auto texture =
        norm2tex::renderMaterialTexture(*variants.back(), size, mm_per_texel, depth);
    char stem[256];
    std::snprintf(stem, sizeof(stem), "%s/%s_%02d", dir.c_str(), config.name.c_str(), k);
    norm2tex::writeImage(std::string(stem) + "_normal.png", texture.normal_map);
    norm2tex::writeImage(std::string(stem) + "_albedo.png", texture.albedo);
  }
  writeVariantsManifest(dir + "/variants.yaml", config, variants, seed);
  std::printf("%d %s variants in %s (variants.yaml lists their parameters)\n", count,
              config.name.c_str(), dir.c_str());
  return 0;
}

/// One row of the gallery: albedo, normal map, and a tilted flat face pressed into the gel
/// without and with the material's texture.
std::vector<cv::Mat3b> galleryRow(const norm2tex::MaterialConfig& config, std::uint64_t seed,
                                  norm2tex::TactileRenderer& renderer) {
  // The textured face must overhang the gel (19.2 x 25.6 mm) even when tilted: 32 mm.
  const int size = std::min(4096, static_cast<int>(std::ceil(32.0 / config.mm_per_texel)));
  const auto material = norm2tex::makeMaterialVariant(config, 0, seed);
  const auto texture =
      norm2tex::renderMaterialTexture(*material, size, config.mm_per_texel, CV_16U);
  norm2tex::BakeOptions options;
  options.range = config.range;
  // As bakeMaterialAtlas: a designed height has no integration drift to remove.
  options.relief_cutoff_mm = 0.0;
  options.relief_cutoff_texels = 0.0;
  const auto atlas = std::make_shared<const norm2tex::HeightAtlas>(norm2tex::bakeHeightAtlas(
      norm2tex::NormalMap::fromImage(texture.normal_map, options.normal_map), options));
  // A face one texture wide, so UV [0, 1] spans it once and the gel sees the texture's middle.
  const double face_m = size * config.mm_per_texel * 1e-3;
  const auto box = std::make_shared<const norm2tex::TexturedMesh>(
      norm2tex::makeBox(Eigen::Vector3d(face_m, face_m, 0.01), face_m));
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitX()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(0.0, 0.0, 0.005 - 0.00035);  // tilted, 0.35 mm deep
  const cv::Size tile(renderer.model().cols, renderer.model().rows);
  std::vector<cv::Mat3b> row;
  const auto crop = [&](const cv::Mat& image) {
    cv::Mat3b bgr;
    if (image.channels() == 4) {
      cv::Mat eight;
      image.convertTo(eight, CV_8U, image.depth() == CV_16U ? 1.0 / 257.0 : 1.0);
      cv::cvtColor(eight, bgr, cv::COLOR_BGRA2BGR);
    } else {
      bgr = image;
    }
    // The texture patch the gel sees (19.2 x 25.6 mm), resized to the tile.
    const double gel_texels_w = renderer.model().gelWidthMm() / config.mm_per_texel;
    const double gel_texels_h = renderer.model().gelHeightMm() / config.mm_per_texel;
    const cv::Rect patch(cvRound((size - gel_texels_w) / 2), cvRound((size - gel_texels_h) / 2),
                         cvRound(gel_texels_w), cvRound(gel_texels_h));
    cv::Mat3b resized;
    cv::resize(bgr(patch & cv::Rect(0, 0, size, size)), resized, tile, 0, 0, cv::INTER_AREA);
    return resized;
  };
  row.push_back(crop(texture.albedo));
  row.push_back(crop(texture.normal_map));
  renderer.setObject(box);
  row.push_back(renderer.render(pose, static_cast<std::int64_t>(seed)).image.clone());
  renderer.setObject(box, atlas, config.beta_mm);
  row.push_back(renderer.render(pose, static_cast<std::int64_t>(seed)).image.clone());
  return row;
}

int writeGallery(const po::variables_map& args, const std::string& output, std::uint64_t seed) {
  norm2tex::TactileRenderer renderer(norm2tex::makeDigitSensorModel());
  std::vector<std::vector<cv::Mat3b>> tiles;
  std::vector<std::string> labels;
  for (const std::string& name : norm2tex::materialNames()) {
    const norm2tex::MaterialConfig config = loadConfig(args, name);
    tiles.push_back(galleryRow(config, seed, renderer));
    char label[96];
    std::snprintf(label, sizeof(label), "%s, beta %.3g mm", name.c_str(), config.beta_mm);
    labels.push_back(label);
  }
  norm2tex::writeImage(
      output, norm2tex::cli::makeContactSheet(tiles, labels,
                                              {"albedo", "normal map", "no texture", "texture"}));
  std::printf("%s: gallery of %zu materials\n", output.c_str(), tiles.size());
  return 0;
}

int run(const norm2tex::cli::Program& program, int argc, char** argv) {
  const po::variables_map args = program.parse(argc, argv);
  if (args["list"].as<bool>()) {
    listMaterials();
    return 0;
  }
  const std::uint64_t seed = static_cast<std::uint64_t>(valueOr<std::int64_t>(args, "seed", 1));
  const std::string output = valueOr<std::string>(args, "output", "");
  if (args["gallery"].as<bool>()) {
    if (output.empty()) throw norm2tex::cli::UsageError("--gallery needs -o GALLERY.png");
    return writeGallery(args, output, seed);
  }
  const std::string name = valueOr<std::string>(args, "material", "");
  if (name.empty()) throw norm2tex::cli::UsageError("missing --material NAME");
  const norm2tex::MaterialConfig config = loadConfig(args, name);
  const int bits = valueOr(args, "bits", 16);
  if (bits != 8 && bits != 16) throw norm2tex::cli::UsageError("--bits must be 8 or 16");
  const int depth = bits == 8 ? CV_8U : CV_16U;
  if (args.count("size") && args.count("mm-per-texel") && !args.count("mesh")) {
    throw norm2tex::cli::UsageError("give --size or --mm-per-texel, not both");
  }
  const double mm_per_texel = valueOr(args, "mm-per-texel", config.mm_per_texel);
  const int size = valueOr(args, "size", config.size);
  if (args.count("variants")) return writeVariants(args, config, seed, size, mm_per_texel, depth);
  if (output.empty()) throw norm2tex::cli::UsageError("missing -o NORMAL.png");

  const auto start = Clock::now();
  const auto material = norm2tex::makeMaterialVariant(config, 0, seed);
  norm2tex::MaterialTexture texture;
  std::string mesh_note;
  if (args.count("mesh")) {
    norm2tex::MeshLoadOptions load_options;
    load_options.scale = valueOr(args, "scale", 1.0);
    const norm2tex::TexturedMesh mesh = [&] {
      const norm2tex::cli::QuietStderr quiet_importer;
      return norm2tex::TexturedMesh::load(args["mesh"].as<std::string>(), load_options);
    }();
    const int padding = valueOr(args, "padding", 4);
    if (mesh.hasUvs()) {
      // The atlas the nodes generate for this mesh (materialAtlasSize), unless --size says.
      norm2tex::MaterialConfig for_mesh = config;
      for_mesh.mm_per_texel = mm_per_texel;
      const int atlas_size =
          args.count("size") ? size : norm2tex::materialAtlasSize(for_mesh, mesh);
      texture = norm2tex::renderMaterialTexture(
          *material, norm2tex::computeUvLayout(mesh, cv::Size(atlas_size, atlas_size)), depth,
          padding);
      mesh_note = ", on the mesh's own UVs, " + std::to_string(atlas_size) + "^2 texels";
    } else {
      norm2tex::UnwrapOptions unwrap;
      unwrap.texture_size = size;
      unwrap.padding_texels = padding;
      const norm2tex::UnwrapResult unwrapped = norm2tex::unwrapUvs(mesh, unwrap);
      const std::string out_mesh = valueOr(
          args, "out-mesh",
          (fs::path(output).parent_path() / (fs::path(output).stem().string() + "_mesh.obj"))
              .string());
      norm2tex::saveMesh(unwrapped.mesh, out_mesh, fs::absolute(output).string());
      texture = norm2tex::renderMaterialTexture(
          *material, norm2tex::computeUvLayout(unwrapped.mesh, cv::Size(size, size)), depth,
          padding);
      char note[512];
      std::snprintf(note, sizeof(note),
                    ", mesh unwrapped into %d charts at %.4g mm per texel -> %s",
                    unwrapped.chart_count, unwrapped.metres_per_uv * 1e3 / size, out_mesh.c_str());
      mesh_note = note;
    }
  } else {
    texture = norm2tex::renderMaterialTexture(*material, size, mm_per_texel, depth);
    char note[96];
    std::snprintf(note, sizeof(note), ", %.4g mm per texel (%.4g mm across)", mm_per_texel,
                  size * mm_per_texel);
    mesh_note = note;
  }
  norm2tex::writeImage(output, texture.normal_map);
  if (args.count("albedo")) {
    norm2tex::writeImage(args["albedo"].as<std::string>(), texture.albedo);
  }
  if (args.count("height-out")) {
    norm2tex::writeImage(args["height-out"].as<std::string>(), texture.height_mm);
  }
  std::printf("%s: %s, seed %llu, %dx%d, %d-bit%s, %.2f s\n", output.c_str(), config.name.c_str(),
              static_cast<unsigned long long>(seed), texture.normal_map.cols,
              texture.normal_map.rows, bits, mesh_note.c_str(),
              std::chrono::duration<double>(Clock::now() - start).count());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const norm2tex::cli::Program program = makeProgram();
  return program.main(argc, argv, [&](int argc, char** argv) { return run(program, argc, argv); });
}
