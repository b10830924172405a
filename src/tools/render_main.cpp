// norm2tex_render: one DIGIT frame of a mesh pressed into the gel, with or without texture.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "cli_arguments.hpp"
#include "contact_sheet.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/common/image_io.hpp"
#include "norm2tex/materials/material_config.hpp"
#include "norm2tex/materials/material_texture.hpp"
#include "norm2tex/mesh/mesh_primitives.hpp"
#include "norm2tex/mesh/object_mesh.hpp"
#include "norm2tex/render/contact_difference.hpp"
#include "norm2tex/render/object_texture.hpp"
#include "norm2tex/render/tactile_renderer.hpp"
#include "package_paths.hpp"
#include "quiet_stderr.hpp"
#include "shear_annotation.hpp"

namespace {

namespace po = norm2tex::cli::po;
using norm2tex::cli::valueOr;

norm2tex::cli::Program makeProgram() {
  norm2tex::cli::Program program(
      "norm2tex_render",
      "norm2tex_render --mesh M --pose \"x y z roll pitch yaw\" [--press-mm D]\n"
      "                       [--normal-map N.png | --atlas H.tiff] [--beta MM] [--scale S]\n"
      "                       [--material NAME] [--sensor digit.yaml] [--background BG.png]\n"
      "                       [--seed S] [--no-noise] [--force-n F] [--conformity on|off]\n"
      "                       -o OUT.png [--depth-out D.tiff] [--mask-out M.png]\n"
      "                       [--contact-stats] [--shear \"FX,FY[,T]\"] [--friction MU]\n"
      "                       [--markers on|off] [--markers-out M.csv] [--annotate GAIN]\n"
      "       norm2tex_render --sheet --mesh M --pose P [--presses 0.5,1,1.5]\n"
      "                       [--normal-map A.png,B.png,...] [--beta MM] ... -o SHEET.png\n"
      "       norm2tex_render --shear-sheet --mesh M --pose P --loads \"FX,FY,T;...\"\n"
      "                       [--annotate GAIN] ... -o SHEET.png",
      "Renders one DIGIT frame of a mesh pressed into the gel, with or without texture, or a\n"
      "contact sheet of several press depths and normal maps (--sheet).");
  program.add()  //
      ("mesh", po::value<std::string>()->value_name("M"),
       "A mesh file (OBJ, STL, PLY, DAE, glTF/GLB) or a primitive: sphere:<radius_mm>, "
       "box:<x_mm>x<y_mm>x<z_mm>.")  //
      ("pose", po::value<std::string>()->value_name("\"x y z roll pitch yaw\""),
       "The object in the gel frame, metres and radians (roll, pitch, yaw about fixed x, y, z). "
       "Gel frame: origin at the centre of the undeformed gel surface, +x right (image "
       "columns), +y down (image rows), +z out of the gel towards the object. An object whose "
       "lowest point is at z = 0 just touches.")  //
      ("press-mm", po::value<double>()->value_name("D"),
       "Then move the object D mm along -z, into the gel.")  //
      ("normal-map", po::value<std::string>()->value_name("N.png"),
       "A normal map, baked to H_global (cached on disk); with --sheet a comma-separated list. "
       "Without --normal-map, --atlas or --material, the mesh's own normal texture (glTF/OBJ "
       "material) is used.")                                                                //
      ("atlas", po::value<std::string>()->value_name("H.tiff"), "An H_global float TIFF.")  //
      ("material", po::value<std::string>()->value_name("NAME"),
       "A procedural material (wood, fabric, rock, smooth, print3d) generated for the mesh's UVs "
       "at its true millimetre scale (a mesh without UVs is unwrapped first), with "
       "config/materials/NAME.yaml's parameters, range and beta.")  //
      ("beta", po::value<double>()->value_name("MM"),
       "Texture depth in mm (default: the material's; 1, a gain, for the mesh's own texture, "
       "baked in mm from the mesh's UV scale; else 0.2 mm, 0.1 mm with --sheet; 0 = "
       "textureless, nothing is baked).")  //
      ("scale", po::value<double>()->value_name("S"),
       "Mesh units to metres (0.001 for meshes in mm; primitives ignore it).")  //
      ("sensor", po::value<std::string>()->value_name("digit.yaml"),
       "The sensor yaml (default: the built-in DIGIT).")  //
      ("background", po::value<std::string>()->value_name("BG.png"),
       "The sensor's no-contact frame (default: the sensor yaml's).")  //
      ("seed", po::value<std::int64_t>()->value_name("S"),
       "The seed of the sensor noise and of the material (default 0).")  //
      ("no-noise", po::bool_switch(), "No sensor noise.")                //
      ("force-n", po::value<double>()->value_name("F"),
       "The press's normal force, N (>= 0): how much of the texture the gel follows when the "
       "sensor's conformity is on; default: the gel law's force for the deepest indentation "
       "(the scenes' default law).")  //
      ("conformity", po::value<std::string>()->value_name("on|off"),
       "Overrides the sensor yaml's conformity.enabled (off: the paper's fixed-depth texture "
       "overlay).")                                                                           //
      ("output,o", po::value<std::string>()->value_name("OUT.png"), "The image (or sheet).")  //
      ("depth-out", po::value<std::string>()->value_name("D.tiff"),
       "Gel deformation, metres, 32-bit float TIFF.")                                 //
      ("mask-out", po::value<std::string>()->value_name("M.png"), "Contact, mono8.")  //
      ("contact-stats", po::bool_switch(),
       "Also print |frame - background| over the contact (B, G, R pooled): its mean and 95th "
       "percentile, grey levels, as real presses are measured (docs/calibration.md).")  //
      ("sheet", po::bool_switch(),
       "A contact sheet (grid PNG): one column per press depth, one row without texture, then "
       "one row per normal map.")  //
      ("presses", po::value<std::string>()->value_name("0.5,1,1.5"),
       "With --sheet: the press depths, mm (default 0.5,1.0,1.5).")  //
      ("shear", po::value<std::string>()->value_name("\"FX,FY[,T]\""),
       "The contact's tangential load: the force the object applies to the gel along x and y "
       "(N) and its twist about +z (N m, x towards y). Moves the gel's surface and its markers "
       "(Cattaneo-Mindlin partial slip on an incompressible layer, docs/sensor.md); prints the "
       "slip fraction and the largest marker displacement.")  //
      ("friction", po::value<double>()->value_name("MU"),
       "Coulomb friction gel-object for --shear (default: the sensor yaml's shear.friction).")  //
      ("markers", po::value<std::string>()->value_name("on|off"),
       "Overrides the sensor yaml's markers.enabled (its grid, or the built-in 9 rows x 7 "
       "columns at 1.8 mm).")  //
      ("markers-out", po::value<std::string>()->value_name("M.csv"),
       "The markers: rest and current position (pixels), displacement (mm), one row each.")  //
      ("annotate", po::value<double>()->value_name("GAIN"),
       "Draw the contact's outline (white), its stick region (green) and each marker's motion "
       "as an arrow GAIN times its length (yellow) over the frame.")  //
      ("shear-sheet", po::bool_switch(),
       "A sheet of one press under several loads (--loads), annotated (--annotate, default "
       "5).")  //
      ("loads", po::value<std::string>()->value_name("\"FX,FY,T;...\""),
       "With --shear-sheet: the loads, one column each, as --shear takes them, ';' between.");
  return program;
}

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

norm2tex::ObjectTexture loadAtlas(const po::variables_map& args,
                                  const norm2tex::TexturedMesh& mesh) {
  norm2tex::TextureSource source;
  source.atlas = valueOr<std::string>(args, "atlas", "");
  if (source.atlas.empty()) source.normal_map = valueOr<std::string>(args, "normal-map", "");
  return loadTextureWithWarning(source, mesh);
}

/// --sheet: rows = no texture, then each normal map; columns = press depths.
int renderSheet(const po::variables_map& args, const norm2tex::SensorModel& model,
                std::shared_ptr<const norm2tex::TexturedMesh> mesh, const std::string& output) {
  std::vector<double> presses;
  for (const std::string& item : splitList(valueOr<std::string>(args, "presses", "0.5,1.0,1.5"))) {
    std::istringstream text(item);
    double press = 0;
    if (!(text >> press) || !(text >> std::ws).eof() || !std::isfinite(press))
      throw norm2tex::cli::UsageError("--presses: not a number: '" + item + "'");
    presses.push_back(press);
  }
  const std::vector<std::string> maps = splitList(valueOr<std::string>(args, "normal-map", ""));
  const double beta = valueOr(args, "beta", 0.1);
  const std::int64_t seed =
      args["no-noise"].as<bool>() ? -1 : valueOr<std::int64_t>(args, "seed", 0);
  const auto shortNumber = [](double value) {
    std::ostringstream text;
    text << value;
    return text.str();
  };
  norm2tex::TactileRenderer renderer(model);
  std::vector<std::vector<cv::Mat3b>> tiles;
  std::vector<std::string> row_labels{"no texture"}, column_labels;
  for (const double press : presses) column_labels.push_back("press " + shortNumber(press) + " mm");
  const std::string pose = args["pose"].as<std::string>();
  const auto addRow = [&](std::shared_ptr<const norm2tex::HeightAtlas> atlas) {
    renderer.setObject(mesh, atlas, atlas ? beta : 0.0);
    tiles.emplace_back();
    for (const double press : presses) {
      tiles.back().push_back(renderer.render(parsePose(pose, press), seed).image.clone());
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

// One press under each of --loads, annotated: where the contact sticks and how the markers move.
int renderShearSheet(const po::variables_map& args, const norm2tex::SensorModel& model,
                     std::shared_ptr<const norm2tex::TexturedMesh> mesh,
                     const Eigen::Isometry3d& pose, std::optional<double> force_n,
                     const std::string& output) {
  if (!args.count("loads")) throw norm2tex::cli::UsageError("--shear-sheet needs --loads");
  const std::vector<std::string> loads =
      norm2tex::cli::splitLoads(args["loads"].as<std::string>());
  if (loads.empty()) throw norm2tex::cli::UsageError("--loads: no load given");
  const double gain = valueOr(args, "annotate", 5.0);
  const std::int64_t seed =
      args["no-noise"].as<bool>() ? -1 : valueOr<std::int64_t>(args, "seed", 0);
  norm2tex::TactileRenderer renderer(model);
  renderer.setObject(std::move(mesh));
  std::vector<std::vector<cv::Mat3b>> tiles(1);
  std::vector<std::string> labels;
  for (const std::string& text : loads) {
    norm2tex::ShearLoad load = norm2tex::cli::parseShearLoad(text, "--loads");
    if (args.count("friction")) load.friction = args["friction"].as<double>();
    const norm2tex::TactileFrame& frame = renderer.render(pose, seed, force_n, load);
    cv::Mat3b tile = frame.image.clone();
    norm2tex::cli::drawShearAnnotations(tile, *frame.shear, gain);
    tiles[0].push_back(tile);
    char label[96];
    std::snprintf(label, sizeof(label), "%.3g,%.3g N %.3g Nmm: slip %.2f", load.force_n.x(),
                  load.force_n.y(), load.torque_nm * 1e3, frame.shear->slipFraction());
    labels.push_back(label);
  }
  char row[64];
  std::snprintf(row, sizeof(row), "arrows x%.3g", gain);
  norm2tex::writeImage(output, norm2tex::cli::makeContactSheet(tiles, {row}, labels));
  std::printf("%s: 1 x %zu shear sheet\n", output.c_str(), loads.size());
  return 0;
}

void writeMarkersCsv(const std::string& path, const norm2tex::ShearFrame& shear) {
  std::ofstream out(path);
  out << "rest_x_px,rest_y_px,current_x_px,current_y_px,displacement_x_mm,displacement_y_mm\n";
  for (const norm2tex::Marker& m : shear.markers) {
    out << m.rest_px.x << "," << m.rest_px.y << "," << m.current_px.x << "," << m.current_px.y
        << "," << m.displacement_mm.x << "," << m.displacement_mm.y << "\n";
  }
  out.close();
  if (!out) throw norm2tex::Error("--markers-out '" + path + "': cannot be written");
}

int run(const norm2tex::cli::Program& program, int argc, char** argv) {
  const po::variables_map args = program.parse(argc, argv);
  if (!args.count("mesh")) throw norm2tex::cli::UsageError("missing --mesh");
  if (!args.count("pose")) throw norm2tex::cli::UsageError("missing --pose");
  const std::string output = valueOr<std::string>(args, "output", "");
  if (output.empty()) throw norm2tex::cli::UsageError("missing -o OUT.png");
  const bool sheet = args["sheet"].as<bool>();
  const std::string mesh_spec = args["mesh"].as<std::string>();
  if (!sheet && valueOr<std::string>(args, "normal-map", "").find(',') != std::string::npos) {
    throw norm2tex::cli::UsageError("several --normal-map files only with --sheet");
  }
  if (sheet && args["contact-stats"].as<bool>()) {
    throw norm2tex::cli::UsageError("--contact-stats measures one frame, not a --sheet");
  }
  const bool shear_sheet = args["shear-sheet"].as<bool>();
  if (shear_sheet && (sheet || args.count("shear"))) {
    throw norm2tex::cli::UsageError("--shear-sheet takes its loads from --loads, without --sheet "
                                    "or --shear");
  }
  if (args.count("loads") && !shear_sheet) {
    throw norm2tex::cli::UsageError("--loads only with --shear-sheet");
  }
  std::optional<norm2tex::ShearLoad> shear;
  if (args.count("shear")) {
    shear = norm2tex::cli::parseShearLoad(args["shear"].as<std::string>(), "--shear");
    if (args.count("friction")) shear->friction = args["friction"].as<double>();
  }
  if (args.count("material") + args.count("normal-map") + args.count("atlas") > 1) {
    throw norm2tex::cli::UsageError("give one of --material, --normal-map and --atlas");
  }
  // Before any work or any file written: depth is float, the image 8-bit colour.
  norm2tex::requireFormatHolds(output, CV_8UC3);
  if (args.count("depth-out")) {
    norm2tex::requireFormatHolds(args["depth-out"].as<std::string>(), CV_32FC1);
  }

  norm2tex::SensorModel model = args.count("sensor")
                                    ? norm2tex::loadSensorModel(args["sensor"].as<std::string>())
                                    : norm2tex::makeDigitSensorModel();
  if (args.count("background")) model.background_image = args["background"].as<std::string>();
  if (args.count("conformity")) {
    const std::string conformity = args["conformity"].as<std::string>();
    if (conformity != "on" && conformity != "off") {
      throw norm2tex::cli::UsageError("--conformity: '" + conformity + "'; valid: on, off");
    }
    model.conformity.enabled = conformity == "on";
  }
  if (args.count("markers")) {
    const std::string markers = args["markers"].as<std::string>();
    if (markers != "on" && markers != "off") {
      throw norm2tex::cli::UsageError("--markers: '" + markers + "'; valid: on, off");
    }
    model.markers.enabled = markers == "on";
  }
  if (args.count("markers-out") && !model.markers.enabled) {
    throw norm2tex::cli::UsageError("--markers-out: the sensor has no markers (--markers on)");
  }
  std::optional<double> force_n;
  if (args.count("force-n")) force_n = args["force-n"].as<double>();
  const auto pose = parsePose(args["pose"].as<std::string>(), valueOr(args, "press-mm", 0.0));
  std::shared_ptr<const norm2tex::TexturedMesh> mesh = [&] {
    const norm2tex::cli::QuietStderr quiet_decoders;
    return loadMesh(mesh_spec, valueOr(args, "scale", 1.0));
  }();
  if (sheet) return renderSheet(args, model, mesh, output);
  if (shear_sheet) return renderShearSheet(args, model, mesh, pose, force_n, output);
  std::shared_ptr<const norm2tex::HeightAtlas> atlas;
  double default_beta = 0.2;
  bool physical_scale = false;  // the atlas holds mm: beta is a gain
  // --beta 0 is a textureless render: nothing to generate or bake.
  const bool textureless = args.count("beta") && args["beta"].as<double>() == 0.0;
  if (textureless) {
    // No texture to load.
  } else if (args.count("material")) {
    // The material is generated for this mesh's own UV layout, so its scale in mm is right.
    const norm2tex::MaterialConfig config = norm2tex::loadMaterialConfig(
        norm2tex::cli::materialConfigPath(args["material"].as<std::string>()));
    norm2tex::TexturedMesh textured = *mesh;
    if (mesh_spec.rfind("sphere:", 0) == 0) {
      // The UV sphere's equirectangular UVs stretch 2:1; an unwrapped copy keeps mm true.
      textured = norm2tex::TexturedMesh(mesh->vertices(), mesh->triangles());
    }
    atlas = std::make_shared<norm2tex::HeightAtlas>(norm2tex::bakeMaterialAtlas(
        config, static_cast<std::uint64_t>(valueOr<std::int64_t>(args, "seed", 0)), textured));
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
  const double beta = valueOr(args, "beta", atlas ? default_beta : 0.0);

  norm2tex::TactileRenderer renderer(model);
  const std::string warning = renderer.setObject(mesh, atlas, beta);
  if (!warning.empty()) std::fprintf(stderr, "norm2tex_render: warning: %s\n", warning.c_str());
  const std::int64_t seed =
      args["no-noise"].as<bool>() ? -1 : valueOr<std::int64_t>(args, "seed", 0);

  const auto start = std::chrono::steady_clock::now();
  const norm2tex::TactileFrame& frame = renderer.render(pose, seed, force_n, shear);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();

  if (args.count("annotate") && frame.shear) {
    cv::Mat3b annotated = frame.image.clone();
    norm2tex::cli::drawShearAnnotations(annotated, *frame.shear, args["annotate"].as<double>());
    norm2tex::writeImage(output, annotated);
  } else {
    norm2tex::writeImage(output, frame.image);
  }
  if (args.count("markers-out")) writeMarkersCsv(args["markers-out"].as<std::string>(), *frame.shear);
  if (args.count("depth-out")) {
    norm2tex::writeImage(args["depth-out"].as<std::string>(), frame.depthMetres());
  }
  if (args.count("mask-out")) {
    norm2tex::writeImage(args["mask-out"].as<std::string>(), frame.contact_mask);
  }
  char texture[96] = "textureless";
  if (frame.textured) {
    std::snprintf(
        texture, sizeof(texture),
        physical_scale ? "textured, beta %.3g (gain on heights in mm)" : "textured, beta %.3g mm",
        beta);
  }
  std::printf("%s: %d contact pixels, %s, %d triangles rasterized, %.2f ms\n", output.c_str(),
              cv::countNonZero(frame.contact_mask), texture, frame.raster.triangles_rasterized, ms);
  if (args["contact-stats"].as<bool>()) {
    const norm2tex::ContactDifference d = norm2tex::measureContactDifference(
        frame.image, renderer.shader().background(), frame.contact_mask);
    std::printf("contact |frame - background|: mean %.1f, 95th percentile %.0f grey levels "
                "(B, G, R over %d pixels)\n",
                d.mean_abs, d.p95_abs, d.pixels);
  }
  if (frame.conformity) {
    const norm2tex::ConformityStats& c = *frame.conformity;
    std::printf("conformity: %.3g N over %.3g mm^2 (mean %.4g MPa); depth followed per band",
                c.normal_force_n, c.contact_area_mm2, c.mean_pressure_mpa);
    for (const norm2tex::ConformityBand& band : c.bands) {
      std::printf(" %.2f (lambda %.3g mm)", band.followed_fraction, band.wavelength_mm);
    }
    std::printf("\n");
  }
  if (shear) {
    double largest = 0.0;
    for (const norm2tex::Marker& m : frame.shear->markers) {
      largest = std::max(largest, std::hypot(double{m.displacement_mm.x}, double{m.displacement_mm.y}));
    }
    double surface = 0.0;
    cv::Mat1f magnitude;
    cv::magnitude(frame.shear->ux_mm, frame.shear->uy_mm, magnitude);
    cv::minMaxLoc(magnitude, nullptr, &surface);
    std::printf("shear: %.2f of the contact slips%s; the surface moves up to %.3f mm",
                frame.shear->slipFraction(), frame.shear->traction.gross_slip ? " (sliding)" : "",
                surface);
    if (!frame.shear->markers.empty()) std::printf(", the markers up to %.3f mm", largest);
    std::printf("\n");
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const norm2tex::cli::Program program = makeProgram();
  return program.main(argc, argv, [&](int argc, char** argv) { return run(program, argc, argv); });
}
