// norm2tex_render: one DIGIT frame of a mesh pressed into the gel, with or without texture.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "cli_arguments.hpp"
#include "contact_sheet.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/common/image_io.hpp"
#include "norm2tex/materials/material_config.hpp"
#include "norm2tex/materials/material_texture.hpp"
#include "norm2tex/mesh/mesh_primitives.hpp"
#include "norm2tex/mesh/object_mesh.hpp"
#include "norm2tex/render/object_texture.hpp"
#include "norm2tex/render/tactile_renderer.hpp"
#include "package_paths.hpp"
#include "quiet_stderr.hpp"

namespace {

constexpr const char* kUsage =
    "usage: norm2tex_render --mesh M --pose \"x y z roll pitch yaw\" [--press-mm D]\n"
    "                       [--normal-map N.png | --atlas H.tiff] [--beta MM] [--scale S]\n"
    "                       [--material NAME] [--sensor digit.yaml] [--background BG.png]\n"
    "                       [--seed S] [--no-noise] [--force-n F] [--conformity on|off]\n"
    "                       -o OUT.png [--depth-out D.tiff] [--mask-out M.png]\n"
    "       norm2tex_render --sheet --mesh M --pose P [--presses 0.5,1,1.5]\n"
    "                       [--normal-map A.png,B.png,...] [--beta MM] ... -o SHEET.png\n"
    "  --mesh: a mesh file (OBJ, STL, PLY, DAE, glTF/GLB) or a primitive: sphere:<radius_mm>,\n"
    "          box:<x_mm>x<y_mm>x<z_mm>\n"
    "  --pose: the object in the gel frame, metres and radians (roll, pitch, yaw about fixed\n"
    "          x, y, z). Gel frame: origin at the centre of the undeformed gel surface, +x\n"
    "          right (image columns), +y down (image rows), +z out of the gel towards the\n"
    "          object. An object whose lowest point is at z = 0 just touches.\n"
    "  --press-mm D: then move the object D mm along -z, into the gel.\n"
    "  --normal-map: baked to H_global (cached on disk); --atlas: an H_global float TIFF.\n"
    "          Without either, the mesh's own normal texture (glTF/OBJ material) is used.\n"
    "  --material NAME: a procedural material (wood, fabric, rock, smooth, print3d) generated\n"
    "          for the mesh's UVs at its true millimetre scale (a mesh without UVs is unwrapped\n"
    "          first), with config/materials/NAME.yaml's parameters, range and beta.\n"
    "  --beta: texture depth in mm (default: the material's; 1, a gain, for the mesh's own\n"
    "          texture, baked in mm from the mesh's UV scale; else 0.2 mm; 0 = textureless,\n"
    "          nothing is baked).\n"
    "  --force-n F: the press's normal force, N (>= 0): how much of the texture the gel\n"
    "          follows when the sensor's conformity is on; default: the gel law's force for\n"
    "          the deepest indentation (the scenes' default law).\n"
    "  --conformity on|off: overrides the sensor yaml's conformity.enabled (off: the paper's\n"
    "          fixed-depth texture overlay).\n"
    "  --scale: mesh units to metres (0.001 for meshes in mm; primitives ignore it).\n"
    "  --depth-out: gel deformation, metres, 32-bit float TIFF. --mask-out: contact, mono8.\n"
    "  --sheet: a contact sheet (grid PNG): one column per press depth, one row without\n"
    "          texture, then one row per normal map.\n";

std::shared_ptr<const norm2tex::TexturedMesh> loadMesh(const std::string& spec, double scale) {
  const bool primitive = spec.rfind("sphere:", 0) == 0 || spec.rfind("box:", 0) == 0;
  try {
    return std::make_shared<norm2tex::TexturedMesh>(norm2tex::loadObjectMesh(spec, scale).mesh);
  } catch (const norm2tex::Error& e) {
    // A malformed primitive is a usage mistake (exit 2); a bad file is an input error (exit 1).
    if (primitive) throw norm2tex::cli::UsageError(std::string("--mesh: ") + e.what());
    throw;
  }
}

Eigen::Isometry3d parsePose(const std::string& text, double press_mm) {
  std::istringstream in(text);
  double v[6];
  for (double& value : v) {
    if (!(in >> value)) {
      throw norm2tex::cli::UsageError("--pose needs 6 numbers \"x y z roll pitch yaw\", got '" +
                                      text + "'");
    }
  }
  std::string extra;
  if (in >> extra)
    throw norm2tex::cli::UsageError("--pose has more than 6 numbers: '" + text + "'");
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = (Eigen::AngleAxisd(v[5], Eigen::Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(v[4], Eigen::Vector3d::UnitY()) *
                   Eigen::AngleAxisd(v[3], Eigen::Vector3d::UnitX()))
                      .toRotationMatrix();
  pose.translation() = Eigen::Vector3d(v[0], v[1], v[2] - press_mm * 1e-3);
  if (!pose.matrix().allFinite()) throw norm2tex::Error("--pose is not finite: '" + text + "'");
  return pose;
}

norm2tex::ObjectTexture loadTextureWithWarning(norm2tex::TextureSource source,
                                               const norm2tex::TexturedMesh& mesh) {
  norm2tex::ObjectTexture texture = norm2tex::loadTextureFile(source, mesh);
  if (!texture.warning.empty()) {
    std::fprintf(stderr, "norm2tex_render: warning: %s\n", texture.warning.c_str());
  }
  return texture;
}

std::shared_ptr<const norm2tex::HeightAtlas> loadTexture(norm2tex::TextureSource source,
                                                         const norm2tex::TexturedMesh& mesh) {
  return loadTextureWithWarning(std::move(source), mesh).atlas;
}

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> items;
  std::istringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    if (!item.empty()) items.push_back(item);
  }
  return items;
}

norm2tex::ObjectTexture loadAtlas(const norm2tex::cli::Arguments& args,
                                  const norm2tex::TexturedMesh& mesh) {
  norm2tex::TextureSource source;
  source.atlas = args.value("--atlas", "");
  if (source.atlas.empty()) source.normal_map = args.value("--normal-map", "");
  return loadTextureWithWarning(source, mesh);
}

/// --sheet: rows = no texture, then each normal map; columns = press depths.
int renderSheet(const norm2tex::cli::Arguments& args, const norm2tex::SensorModel& model,
                std::shared_ptr<const norm2tex::TexturedMesh> mesh, const std::string& output) {
  std::vector<double> presses;
  for (const std::string& item : splitList(args.value("--presses", "0.5,1.0,1.5"))) {
    std::istringstream text(item);
    double press = 0;
    if (!(text >> press))
      throw norm2tex::cli::UsageError("--presses: not a number: '" + item + "'");
    presses.push_back(press);
  }
  const std::vector<std::string> maps = splitList(args.value("--normal-map", ""));
  const double beta = args.number("--beta", 0.1);
  const std::int64_t seed = args.flag("--no-noise") ? -1 : args.integer("--seed", 0);
  const auto shortNumber = [](double value) {
    std::ostringstream text;
    text << value;
    return text.str();
  };
  norm2tex::TactileRenderer renderer(model);
  std::vector<std::vector<cv::Mat3b>> tiles;
  std::vector<std::string> row_labels{"no texture"}, column_labels;
  for (const double press : presses) column_labels.push_back("press " + shortNumber(press) + " mm");
  const auto addRow = [&](std::shared_ptr<const norm2tex::HeightAtlas> atlas) {
    renderer.setObject(mesh, atlas, atlas ? beta : 0.0);
    tiles.emplace_back();
    for (const double press : presses) {
      tiles.back().push_back(
          renderer.render(parsePose(*args.value("--pose"), press), seed).image.clone());
    }
  };
  addRow(nullptr);
  for (const std::string& map : maps) {
    addRow([&] {
      const norm2tex::cli::QuietStderr quiet_decoders;
      norm2tex::TextureSource source;
      source.normal_map = map;
      return loadTexture(source, *mesh);
    }());
    row_labels.push_back(std::filesystem::path(map).stem().string() + ", beta " +
                         shortNumber(beta) + " mm");
  }
  norm2tex::writeImage(output, norm2tex::cli::makeContactSheet(tiles, row_labels, column_labels));
  std::printf("%s: %zu x %zu contact sheet\n", output.c_str(), tiles.size(), presses.size());
  return 0;
}

int run(int argc, char** argv) {
  const norm2tex::cli::Arguments args(
      argc, argv,
      {"--mesh", "--pose", "--press-mm", "--normal-map", "--atlas", "--beta", "--scale", "--sensor",
       "--background", "--seed", "-o", "--depth-out", "--mask-out", "--presses", "--material",
       "--force-n", "--conformity"},
      {"--no-noise", "--sheet", "-h", "--help"});
  if (args.flag("-h") || args.flag("--help")) {
    std::cout << kUsage;
    return 0;
  }
  if (!args.has("--mesh")) throw norm2tex::cli::UsageError("missing --mesh");
  if (!args.has("--pose")) throw norm2tex::cli::UsageError("missing --pose");
  const std::string output = args.value("-o", "");
  if (output.empty()) throw norm2tex::cli::UsageError("missing -o OUT.png");
  if (!args.flag("--sheet") && args.value("--normal-map", "").find(',') != std::string::npos) {
    throw norm2tex::cli::UsageError("several --normal-map files only with --sheet");
  }
  if (args.has("--material") + args.has("--normal-map") + args.has("--atlas") > 1) {
    throw norm2tex::cli::UsageError("give one of --material, --normal-map and --atlas");
  }
  if (args.has("--normal-map") && args.has("--atlas")) {
    throw norm2tex::cli::UsageError("give --normal-map or --atlas, not both");
  }
  // Before any work or any file written: depth is float, the image 8-bit colour.
  norm2tex::requireFormatHolds(output, CV_8UC3);
  if (const auto depth_out = args.value("--depth-out")) {
    norm2tex::requireFormatHolds(*depth_out, CV_32FC1);
  }

  norm2tex::SensorModel model = args.has("--sensor")
                                    ? norm2tex::loadSensorModel(*args.value("--sensor"))
                                    : norm2tex::makeDigitSensorModel();
  if (const auto background = args.value("--background")) model.background_image = *background;
  if (const auto conformity = args.value("--conformity")) {
    if (*conformity != "on" && *conformity != "off") {
      throw norm2tex::cli::UsageError("--conformity: '" + *conformity + "'; valid: on, off");
    }
    model.conformity.enabled = *conformity == "on";
  }
  std::optional<double> force_n;
  if (args.has("--force-n")) force_n = args.number("--force-n", 0.0);
  const auto pose = parsePose(*args.value("--pose"), args.number("--press-mm", 0.0));
  std::shared_ptr<const norm2tex::TexturedMesh> mesh = [&] {
    const norm2tex::cli::QuietStderr quiet_decoders;
    return loadMesh(*args.value("--mesh"), args.number("--scale", 1.0));
  }();
  if (args.flag("--sheet")) return renderSheet(args, model, mesh, output);
  std::shared_ptr<const norm2tex::HeightAtlas> atlas;
  double default_beta = 0.2;
  bool physical_scale = false;  // the atlas holds mm: beta is a gain
  // --beta 0 is a textureless render: nothing to generate or bake.
  const bool textureless = args.has("--beta") && args.number("--beta", 0.0) == 0.0;
  if (textureless) {
    // No texture to load.
  } else if (const auto material = args.value("--material")) {
    // The material is generated for this mesh's own UV layout, so its scale in mm is right.
    const norm2tex::MaterialConfig config =
        norm2tex::loadMaterialConfig(norm2tex::cli::materialConfigPath(*material));
    norm2tex::TexturedMesh textured = *mesh;
    if (args.value("--mesh")->rfind("sphere:", 0) == 0) {
      // The UV sphere's equirectangular UVs stretch 2:1; an unwrapped copy keeps mm true.
      textured = norm2tex::TexturedMesh(mesh->vertices(), mesh->triangles());
    }
    atlas = std::make_shared<norm2tex::HeightAtlas>(norm2tex::bakeMaterialAtlas(
        config, static_cast<std::uint64_t>(args.integer("--seed", 0)), textured));
    mesh = std::make_shared<const norm2tex::TexturedMesh>(std::move(textured));
    default_beta = config.beta_mm;
  } else {
    const norm2tex::cli::QuietStderr quiet_decoders;
    const norm2tex::ObjectTexture texture = loadAtlas(args, *mesh);
    atlas = texture.atlas;
    // A mesh's own texture comes at physical scale (mm): its beta is a gain of 1.
    if (texture.beta_mm > 0.0) default_beta = texture.beta_mm;
    physical_scale = texture.physical_scale;
    if (atlas) std::printf("texture: %s\n", texture.description.c_str());
  }
  const double beta = args.number("--beta", atlas ? default_beta : 0.0);

  norm2tex::TactileRenderer renderer(model);
  const std::string warning = renderer.setObject(mesh, atlas, beta);
  if (!warning.empty()) std::fprintf(stderr, "norm2tex_render: warning: %s\n", warning.c_str());
  const std::int64_t seed = args.flag("--no-noise") ? -1 : args.integer("--seed", 0);

  const auto start = std::chrono::steady_clock::now();
  const norm2tex::TactileFrame& frame = renderer.render(pose, seed, force_n);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();

  norm2tex::writeImage(output, frame.image);
  if (const auto depth_out = args.value("--depth-out"))
    norm2tex::writeImage(*depth_out, frame.depthMetres());
  if (const auto mask_out = args.value("--mask-out"))
    norm2tex::writeImage(*mask_out, frame.contact_mask);
  char texture[96] = "textureless";
  if (frame.textured) {
    std::snprintf(
        texture, sizeof(texture),
        physical_scale ? "textured, beta %.3g (gain on heights in mm)" : "textured, beta %.3g mm",
        beta);
  }
  std::printf("%s: %d contact pixels, %s, %d triangles rasterized, %.2f ms\n", output.c_str(),
              cv::countNonZero(frame.contact_mask), texture, frame.raster.triangles_rasterized, ms);
  if (frame.conformity) {
    const norm2tex::ConformityStats& c = *frame.conformity;
    std::printf("conformity: %.3g N over %.3g mm^2 (mean %.4g MPa); depth followed per band",
                c.normal_force_n, c.contact_area_mm2, c.mean_pressure_mpa);
    for (const norm2tex::ConformityBand& band : c.bands) {
      std::printf(" %.2f (lambda %.3g mm)", band.followed_fraction, band.wavelength_mm);
    }
    std::printf("\n");
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return norm2tex::cli::runMain("norm2tex_render", kUsage, run, argc, argv);
}
