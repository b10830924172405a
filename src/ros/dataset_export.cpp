#include "dataset_export.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <set>
#include <sstream>

#include <opencv2/imgcodecs.hpp>

#include "norm2tex/common/error.hpp"
#include "norm2tex/common/npy_file.hpp"
#include "tactile_bag_reader.hpp"

namespace norm2tex {
namespace fs = std::filesystem;
namespace {

void writeImage(const fs::path& path, const cv::Mat& image) {
  fs::create_directories(path.parent_path());
  bool ok = false;
  try {
    // OpenCV's default PNG settings (level 1, RLE strategy) are its fastest; naming a level
    // switches to the default strategy, 2-3x slower here.
    ok = cv::imwrite(path.string(), image);
  } catch (const cv::Exception& e) {
    throw Error("writing '" + path.string() + "' failed: " + e.what());
  }
  if (!ok) throw Error("writing '" + path.string() + "' failed (disk full or unwritable?)");
}

/// CSV field: quoted when it holds a comma, quote or newline.
std::string csv(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

/// One row per marker of the grid, row by row.
void writeMarkers(const fs::path& path, const TactileMarkers& m) {
  fs::create_directories(path.parent_path());
  std::ofstream out(path);
  out << "marker,row,col,rest_x_px,rest_y_px,x_px,y_px,dx_mm,dy_mm\n";
  const std::size_t count = m.rest_px.size();
  if (m.current_px.size() != count || m.displacement_mm.size() != count ||
      count != static_cast<std::size_t>(m.rows) * m.cols) {
    throw Error("markers of " + std::to_string(m.rows) + " x " + std::to_string(m.cols) +
                " with " + std::to_string(count) + " rest, " +
                std::to_string(m.current_px.size()) + " current and " +
                std::to_string(m.displacement_mm.size()) + " displacements: inconsistent");
  }
  out << std::setprecision(9);
  for (std::size_t i = 0; i < count; ++i) {
    out << i << "," << i / m.cols << "," << i % m.cols << "," << m.rest_px[i].x << ","
        << m.rest_px[i].y << "," << m.current_px[i].x << "," << m.current_px[i].y << ","
        << m.displacement_mm[i].x << "," << m.displacement_mm[i].y << "\n";
  }
  if (!out) throw Error("writing '" + path.string() + "' failed (disk full or unwritable?)");
}

}  // namespace

ExportSummary exportDataset(const std::vector<std::string>& bags, const ExportOptions& options,
                            const std::function<void(std::uint64_t)>& progress) {
  if (options.depth_format != "png16" && options.depth_format != "tiff") {
    throw Error("depth format '" + options.depth_format + "' is not valid; valid: png16, tiff");
  }
  const fs::path out(options.out_dir);
  std::error_code ec;
  if (fs::exists(out) && !fs::is_directory(out)) {
    throw Error("output '" + out.string() + "' exists and is not a directory");
  }
  if (fs::exists(out) && !fs::is_empty(out, ec) && !options.force) {
    throw Error("output directory '" + out.string() +
                "' is not empty; use --force to write into it");
  }
  fs::create_directories(out, ec);
  std::ofstream labels(out / "labels.csv");
  if (ec || !labels) throw Error("output directory '" + out.string() + "' cannot be written");
  std::map<std::string, cv::Mat3b> given_backgrounds;
  for (const auto& [sensor, file] : options.background_files) {
    cv::Mat image = cv::imread(file, cv::IMREAD_COLOR);
    if (image.empty()) throw Error("background '" + file + "' cannot be read as an image");
    given_backgrounds[sensor] = image;
  }

  TactileBagReader reader(bags);
  // Columns added later go at the end, so readers by position keep working.
  labels << "raw,diff,depth,material,variant,sensor,stamp,episode,object,beta,seed,scenario,"
            "shard,press,press_depth,in_contact,normal_force,max_indentation,contact_area,bag,"
            "twist_moment,slip_fraction,markers,shear\n";
  ExportSummary summary;
  std::set<std::string> names;
  reader.forEachSample([&](const TactileSample& s) {
    const EpisodeInfo& e = s.episode;
    const std::string material = e.material.empty() ? "unlabelled" : e.material;
    std::ostringstream name;
    name << s.sensor << "_s" << e.shard << "_" << s.stamp.toNSec();
    if (!names.insert(name.str()).second) {
      throw Error("two frames of " + s.sensor + " at " + std::to_string(s.stamp.toSec()) +
                  " s in shard " + std::to_string(e.shard) +
                  ": are bags of different recordings mixed? Export them separately");
    }
    const std::string file = material + "/" + name.str();
    const std::string raw = "raw/" + file + ".png", diff = "diff/" + file + ".png";
    writeImage(out / raw, s.image);

    auto background = reader.backgrounds().find(s.sensor);
    const cv::Mat3b* bg = background != reader.backgrounds().end() ? &background->second : nullptr;
    auto given = given_backgrounds.find(s.sensor);
    if (given != given_backgrounds.end()) bg = &given->second;
    if (!bg) {
      throw Error("no background for " + s.sensor + " (the bags hold no " + s.sensor +
                  "/background); give one with --background " + s.sensor + "=FILE.png");
    }
    if (bg->size() != s.image.size()) {
      throw Error("the background of " + s.sensor + " is " + std::to_string(bg->cols) + " x " +
                  std::to_string(bg->rows) + ", the images " + std::to_string(s.image.cols) +
                  " x " + std::to_string(s.image.rows));
    }
    cv::Mat difference;
    cv::subtract(s.image, *bg, difference, cv::noArray(), CV_16SC3);
    difference.convertTo(difference, CV_8UC3, 1.0, 128.0);  // saturates to 0..255
    writeImage(out / diff, difference);

    std::string depth;
    if (!s.depth_m.empty()) {
      if (options.depth_format == "png16") {
        depth = "depth/" + file + ".png";
        cv::Mat micrometres;
        s.depth_m.convertTo(micrometres, CV_16UC1, 1e6);  // rounds, saturates at 65.535 mm
        writeImage(out / depth, micrometres);
      } else {
        depth = "depth/" + file + ".tiff";
        writeImage(out / depth, s.depth_m);
      }
    }
    std::string markers;
    if (s.has_markers) {
      markers = "markers/" + file + ".csv";
      writeMarkers(out / markers, s.markers);
      ++summary.frames_with_markers;
    }
    std::string shear;
    if (!s.shear_m.empty()) {
      shear = "shear/" + file + ".npy";
      fs::create_directories((out / shear).parent_path());
      writeNpy((out / shear).string(), s.shear_m);
      ++summary.frames_with_shear;
    }
    const TactileContact& c = s.contact;
    labels << raw << "," << diff << "," << depth << "," << csv(material) << "," << e.variant << ","
           << s.sensor << "," << s.stamp.toNSec() << "," << e.episode << "," << csv(e.object) << ","
           << e.beta << "," << e.seed << "," << csv(e.scenario) << "," << e.shard << "," << e.press
           << "," << e.press_depth << "," << (s.has_contact ? (c.in_contact ? 1 : 0) : -1) << ","
           << (s.has_contact ? c.normal_force : NAN) << ","
           << (s.has_contact ? c.max_indentation : NAN) << ","
           << (s.has_contact ? c.contact_area : NAN) << "," << csv(fs::path(s.bag).filename().string())
           << "," << (s.has_contact ? c.twist_moment : NAN) << ","
           << (s.has_contact ? c.slip_fraction : NAN) << "," << markers << "," << shear << "\n";
    if (!labels) throw Error("writing labels.csv failed (disk full?)");
    ++summary.frames;
    ++summary.frames_per_material[material];
    if (progress) progress(summary.frames);
  });
  labels.close();
  if (!labels) throw Error("writing labels.csv failed (disk full?)");
  summary.warnings = reader.warnings();

  std::ofstream yaml(out / "export.yaml");
  yaml << "# norm2tex_export: frames of dataset_recorder bags for training\n"
       << "frames: " << summary.frames << "\n"
       << "frames_per_material:\n";
  for (const auto& [material, n] : summary.frames_per_material) {
    yaml << "  " << material << ": " << n << "\n";
  }
  yaml << "encodings:\n"
       << "  raw: BGR PNG, the sensor image as published\n"
       << "  diff: BGR PNG, image - background + 128 (clamped to 0..255)\n"
       << "  depth: "
       << (options.depth_format == "png16" ? "uint16 PNG, gel indentation in micrometres"
                                            : "float32 TIFF, gel indentation in metres")
       << "\n";
  if (summary.frames_with_markers > 0) {
    yaml << "  markers: CSV per frame, a row per marker: grid row and column, rest and current "
            "position (pixels, x = column, y = row), displacement (mm, gel frame)\n";
  }
  if (summary.frames_with_shear > 0) {
    yaml << "  shear: NumPy .npy per frame, float32 (rows, cols, 2): the gel surface's lateral "
            "displacement at each pixel, metres, gel frame x, y\n";
  }
  yaml << "bags:\n";
  for (const std::string& bag : bags) yaml << "  - '" << bag << "'\n";
  if (!yaml) throw Error("writing export.yaml failed (disk full?)");
  return summary;
}

}  // namespace norm2tex
