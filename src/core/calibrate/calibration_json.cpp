#include "norm2tex/calibrate/calibration_json.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <vector>

#include "common/json_writer.hpp"
#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

void writeMeasures(JsonWriter& json, const ImageSimilarity& s) {
  json.key("ssim").value(s.ssim);
  json.key("contact_ssim").value(s.ssim_in_mask);
  json.key("psnr_db").value(s.psnr_db);
  json.key("mean_abs_diff").value(s.mean_abs_diff);
}

void writeSet(JsonWriter& json, const std::vector<PressFrameComparison>& presses,
              double variance_explained) {
  json.beginObject();
  json.key("presses").value(static_cast<int>(presses.size()));
  json.key("variance_explained").value(variance_explained);
  json.key("median").beginObject();
  writeMeasures(json, medianSimilarity(presses));
  json.endObject();
  json.key("median_bare_background").beginObject();
  writeMeasures(json, medianSimilarity(presses, &PressFrameComparison::bare_background));
  json.endObject();
  json.endObject();
}

void writePress(JsonWriter& json, const PressFrameComparison& press) {
  json.beginObject();
  json.key("image").value(press.name);
  json.key("held_out").value(press.held_out);
  json.key("labelled").value(press.labelled);
  json.key("centre_x_px").value(press.circle.centre_px.x);
  json.key("centre_y_px").value(press.circle.centre_px.y);
  json.key("radius_px").value(press.circle.radius_px);
  json.key("contact_radius_px").value(press.contact_radius_px);
  json.key("depth_mm").value(press.depth_mm);
  writeMeasures(json, press.similarity);
  json.key("bare_background").beginObject();
  writeMeasures(json, press.bare_background);
  json.endObject();
  json.endObject();
}

}  // namespace

std::string calibrationReportJson(const CalibrationResult& result, double ball_diameter_mm) {
  JsonWriter json;
  json.beginObject();
  json.key("ball_diameter_mm").value(ball_diameter_mm);
  json.key("mm_per_pixel").value(result.fit.geometry.mm_per_pixel);
  json.key("radius_factor").value(result.fit.geometry.radius_factor);
  json.key("rim_shadow_sigma_mm").value(result.fit.shading.shadow_sigma_mm);
  json.key("held_out");
  writeSet(json, result.held_out_frames, result.held_out.variance_explained);
  // A judged sensor (judgeSensor) was fitted on none of these presses: "fitted" is null.
  json.key("judged").value(result.training_frames.empty());
  json.key("fitted");
  if (result.training_frames.empty()) {
    json.value(std::numeric_limits<double>::quiet_NaN());
  } else {
    writeSet(json, result.training_frames, result.fit.variance_explained);
  }
  std::vector<PressFrameComparison> presses = result.held_out_frames;
  presses.insert(presses.end(), result.training_frames.begin(), result.training_frames.end());
  std::sort(presses.begin(), presses.end(),
            [](const PressFrameComparison& a, const PressFrameComparison& b) {
              return a.index < b.index;
            });
  json.key("presses").beginArray();
  for (const PressFrameComparison& press : presses) writePress(json, press);
  json.endArray();
  json.endObject();
  return json.text();
}

void checkJsonReportPath(const std::string& path) {
  namespace fs = std::filesystem;
  if (path.empty()) throw Error("JSON report: the path is empty");
  const fs::path target(path);
  const fs::path directory = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(directory, ec)) {
    throw Error("JSON report '" + path + "' cannot be written: directory '" + directory.string() +
                "' does not exist or is not a directory");
  }
  if (fs::is_directory(target, ec)) {
    throw Error("JSON report '" + path + "' cannot be written: it is a directory");
  }
  // Opening for appending leaves an existing file as it is; a file this probe creates is removed
  // again, so a calibration that fails later leaves no empty report behind.
  const bool existed = fs::exists(target, ec);
  errno = 0;
  const bool writable = static_cast<bool>(std::ofstream(path, std::ios::app));
  const int error = errno;
  if (!existed) fs::remove(target, ec);
  if (!writable) {
    throw Error("JSON report '" + path + "' cannot be written" +
                (error != 0 ? std::string(": ") + std::strerror(error) : std::string()));
  }
}

void writeCalibrationReportJson(const std::string& path, const CalibrationResult& result,
                                double ball_diameter_mm) {
  checkJsonReportPath(path);
  const std::string text = calibrationReportJson(result, ball_diameter_mm);
  errno = 0;
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  if (file) file << text;
  if (file) file.close();
  if (!file) {
    throw Error("JSON report '" + path + "' cannot be written" +
                (errno != 0 ? std::string(": ") + std::strerror(errno) : std::string()));
  }
}

}  // namespace norm2tex
