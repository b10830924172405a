// norm2tex_calibrate: fits a sensor yaml to your own DIGIT from no-contact frames and a few
// ball presses (see norm2tex/calibrate/sensor_calibration.hpp for the method).

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "cli_arguments.hpp"
#include "norm2tex/calibrate/calibration_json.hpp"
#include "norm2tex/calibrate/press_scale.hpp"
#include "norm2tex/calibrate/calibration_report.hpp"
#include "norm2tex/calibrate/press_labels.hpp"
#include "norm2tex/calibrate/sensor_calibration.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/common/image_io.hpp"
#include "norm2tex/common/memory_reuse.hpp"
#include "norm2tex/render/sensor_model.hpp"

namespace {

using norm2tex::Error;
using norm2tex::cli::UsageError;

namespace po = norm2tex::cli::po;
using norm2tex::cli::valueOr;

norm2tex::cli::Program makeProgram() {
  norm2tex::cli::Program program(
      "norm2tex_calibrate",
      "norm2tex_calibrate --background BG.png [BG2.png ...] --presses P1.png P2.png ...\n"
      "                          --ball-diameter-mm D [--mm-per-pixel S] [--labels labels.csv]\n"
      "                          [--size WxH] [--sensor base.yaml] [--holdout F]\n"
      "                          [--scale-presses A.png B.png --scale-distance-mm D]\n"
      "                          -o SENSOR.yaml [--report REPORT.png] [--json REPORT.json]\n"
      "       norm2tex_calibrate --judge SENSOR.yaml --background BG.png ... --presses P.png ...\n"
      "                          --ball-diameter-mm D [--labels labels.csv] [--size WxH]\n"
      "                          [--report REPORT.png] [--json REPORT.json]",
      "Fits a sensor yaml to your DIGIT (or, with --sensor, another sensor such as\n"
      "config/gelsight_mini.yaml) from no-contact frames and a few ball presses: the scale\n"
      "(unless --mm-per-pixel), the calibrated shading with its rim shadow, and the noise of\n"
      "your no-contact frames, which become the sensor's background (written beside the yaml as\n"
      "<name>_background.png).");
  program.add()  //
      ("background",
       po::value<std::vector<std::string>>()->multitoken()->composing()->value_name("BG.png ..."),
       "No-contact frames (averaged).")  //
      ("presses",
       po::value<std::vector<std::string>>()->multitoken()->composing()->value_name("P.png ..."),
       "Frames of one ball press each, at different places (at least 4; 10-50 recommended), "
       "turned as your driver publishes them (portrait for a DIGIT).")  //
      ("ball-diameter-mm", po::value<double>()->value_name("D"),
       "The pressing ball's diameter, mm.")  //
      ("mm-per-pixel", po::value<double>()->value_name("S"),
       "The scale, in (0, 1], if you know it (recommended); otherwise it is fitted, but ball "
       "presses pin it only weakly (the range that fits as well is printed).")  //
      ("labels", po::value<std::string>()->value_name("labels.csv"),
       "CSV lines 'file,centre_x_px,centre_y_px,radius_px' (file: as given or its base name, so "
       "paths from another machine work; an optional header line; CRLF is fine) for presses "
       "whose contact circle you know; the others are detected.")  //
      ("size", po::value<std::string>()->value_name("WxH"),
       "Resample every frame to this size first (e.g. 240x320 for VGA captures of a QVGA "
       "sensor). Default: the frames' own size.")  //
      ("sensor", po::value<std::string>()->value_name("base.yaml"),
       "The sensor yaml to start from (gel, camera, image orientation); default: the built-in "
       "DIGIT.")  //
      ("holdout", po::value<double>()->value_name("F"),
       "The share of the presses held out to judge the fit (default 0.3).")  //
      ("scale-presses",
       po::value<std::vector<std::string>>()->multitoken()->value_name("A.png B.png"),
       "Two frames of a press (the ball, or a pin) moved --scale-distance-mm along the gel "
       "between them: the distance between their contact centres measures the scale, used as "
       "--mm-per-pixel would be.")  //
      ("scale-distance-mm", po::value<double>()->value_name("D"),
       "How far the press moved between the two --scale-presses frames, mm.")  //
      ("judge", po::value<std::string>()->value_name("SENSOR.yaml"),
       "Fit nothing: judge this calibrated sensor on the presses given (another recording of the "
       "same unit, or another unit), every one held out, as a fit's held-out presses are "
       "judged. Writes no sensor yaml.")  //
      ("output,o", po::value<std::string>()->value_name("SENSOR.yaml"),
       "The fitted sensor yaml.")  //
      ("report", po::value<std::string>()->value_name("REPORT.png"),
       "A side-by-side image of held-out presses: real | render | difference.")  //
      ("json", po::value<std::string>()->value_name("REPORT.json"),
       "A machine-readable report: every press's circle, depth and render-vs-real SSIM (frame and "
       "contact), PSNR and mean |diff|, their medians and the variance explained.");
  return program;
}

cv::Size parseSize(const std::string& text) {
  int width = 0, height = 0;
  char x = 0;
  std::istringstream in(text);
  if (!(in >> width >> x >> height) || x != 'x' || width < 8 || height < 8 || !in.eof()) {
    throw UsageError("--size '" + text + "' is not valid; give WxH, e.g. 240x320");
  }
  return {width, height};
}

norm2tex::NamedFrame loadFrame(const std::string& path, const std::optional<cv::Size>& size) {
  cv::Mat image = norm2tex::readImage(path, cv::IMREAD_COLOR, "frame");
  if (size && image.size() != *size) {
    const bool portrait = image.rows > image.cols, wanted_portrait = size->height > size->width;
    if (portrait != wanted_portrait) {
      throw Error("frame '" + path + "' is " + std::to_string(image.cols) + " x " +
                  std::to_string(image.rows) + (portrait ? " (portrait)" : " (landscape)") +
                  " but --size asks for " + std::to_string(size->width) + " x " +
                  std::to_string(size->height) +
                  "; rotate it the way your driver publishes frames");
    }
    cv::resize(image, image, *size, 0, 0, cv::INTER_AREA);
  }
  return {path, image};
}

// The sensor to start from, at the frames' size: the built-in DIGIT at QVGA or VGA, or
// --sensor's model; other sizes keep the gel and scale the pixels. Frames turned the other way
// than the sensor's would be stretched across the wrong axis: an error.
norm2tex::SensorModel baseModel(const po::variables_map& args, cv::Size frame_size) {
  const bool given = args.count("sensor") > 0;
  norm2tex::SensorModel model =
      given ? norm2tex::loadSensorModel(args["sensor"].as<std::string>())
            : norm2tex::makeDigitSensorModel(frame_size == cv::Size(480, 640));
  const auto orientation = [](int width, int height) {
    return width > height ? "landscape" : "portrait";
  };
  if (frame_size.width != frame_size.height && model.cols != model.rows &&
      (frame_size.width > frame_size.height) != (model.cols > model.rows)) {
    const std::string sensor =
        given ? "the sensor's (" + args["sensor"].as<std::string>() + ")" : "a DIGIT's";
    throw Error("the first background frame is " + std::to_string(frame_size.width) + " x " +
                std::to_string(frame_size.height) + " (" +
                orientation(frame_size.width, frame_size.height) + ") but " + sensor +
                " frames are " + orientation(model.cols, model.rows) + " (" +
                std::to_string(model.rows) + " rows x " + std::to_string(model.cols) +
                " columns as its driver publishes them); rotate your frames the way your driver "
                "does" +
                (given ? "" : ", or give your sensor's yaml (--sensor config/gelsight_mini.yaml)"));
  }
  if (model.imageSize() != frame_size) {
    const double factor = static_cast<double>(model.cols) / frame_size.width;
    model.mm_per_pixel *= factor;
    model.fx /= factor;
    model.fy /= factor;
    model.cols = frame_size.width;
    model.rows = frame_size.height;
    model.cx = 0.5 * model.cols - 0.5;
    model.cy = 0.5 * model.rows - 0.5;
  }
  model.background_image.clear();
  return model;
}

// Labels CSV (norm2tex/calibrate/press_labels.hpp): matched to the presses by path or base name.
std::vector<std::optional<norm2tex::PressCircle>> loadLabels(
    const std::string& path, const std::vector<norm2tex::NamedFrame>& presses) {
  std::vector<std::string> names;
  for (const norm2tex::NamedFrame& press : presses) names.push_back(press.name);
  return norm2tex::matchPressLabels(norm2tex::readPressLabels(path), names,
                                    "labels '" + path + "'");
}

// Ball presses pin the scale only weakly (ScaleSearch): say so when the fit ran to an end of the
// searched range or scales far apart fit as well.
void warnAboutFittedScale(const norm2tex::ShadingFit& fit) {
  const norm2tex::ScaleSearch& search = fit.scale_search;
  if (fit.scale_at_search_bound) {
    std::fprintf(stderr,
                 "norm2tex_calibrate: warning: the fitted scale (%.4f mm/px) is at the end of the "
                 "searched range: the presses do not pin it down (a response fitted to your unit "
                 "absorbs most of a change of scale, and a real DIGIT's presses fitted best at the "
                 "smallest scale); measure it (a ruler pressed into the gel) and pass "
                 "--mm-per-pixel\n",
                 fit.geometry.mm_per_pixel);
  } else if (!search.profile.empty() && search.range_max > 1.1 * search.range_min) {
    std::fprintf(stderr,
                 "norm2tex_calibrate: warning: scales from %.4f to %.4f mm/px fit the presses "
                 "about as well; if you know yours, pass --mm-per-pixel\n",
                 search.range_min, search.range_max);
  }
}

// --report and --json, then the summary a fit and a judgement print alike.
void reportOn(const po::variables_map& args, const std::string& json_path,
              const norm2tex::CalibrationResult& result, const norm2tex::CalibrationInput& input,
              std::chrono::steady_clock::time_point start, const std::string& what) {
  if (args.count("report")) {
    norm2tex::writeImage(args["report"].as<std::string>(), norm2tex::makeCalibrationReport(result));
  }
  if (args.count("json")) {
    norm2tex::writeCalibrationReportJson(json_path, result, input.ball_diameter_mm);
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%s on %zu presses in %.1f s\n", what.c_str(), input.presses.size(), seconds);
  for (const std::string& line : norm2tex::describeFitQuality(result)) {
    std::printf("  %s\n", line.c_str());
  }
}

int run(const norm2tex::cli::Program& program, int argc, char** argv) {
  // The fit renders thousands of presses through frame-sized temporaries: reused, not faulted
  // in afresh each time (~3x faster calibration).
  norm2tex::keepFreedMemoryForReuse();
  const po::variables_map args = program.parse(argc, argv);
  if (!args.count("background")) throw UsageError("missing --background");
  if (!args.count("presses")) throw UsageError("missing --presses");
  if (!args.count("ball-diameter-mm")) throw UsageError("missing --ball-diameter-mm");
  const bool judging = args.count("judge") > 0;
  const std::string output = valueOr<std::string>(args, "output", "");
  if (judging) {
    if (!output.empty()) throw UsageError("--judge fits nothing: it writes no -o SENSOR.yaml");
    if (args.count("sensor") || args.count("holdout")) {
      throw UsageError("--judge takes the calibrated sensor as it is: no --sensor or --holdout");
    }
  } else if (output.empty()) {
    throw UsageError("missing -o SENSOR.yaml");
  }
  const std::string json_path = valueOr<std::string>(args, "json", "");
  if (args.count("json")) norm2tex::checkJsonReportPath(json_path);  // before the fit's work

  const auto start = std::chrono::steady_clock::now();
  std::optional<cv::Size> size;
  if (args.count("size")) size = parseSize(args["size"].as<std::string>());
  norm2tex::CalibrationInput input;
  for (const std::string& path : args["background"].as<std::vector<std::string>>()) {
    input.backgrounds.push_back(loadFrame(path, size));
  }
  for (const std::string& path : args["presses"].as<std::vector<std::string>>()) {
    input.presses.push_back(loadFrame(path, size));
  }
  input.ball_diameter_mm = args["ball-diameter-mm"].as<double>();
  if (args.count("mm-per-pixel")) input.mm_per_pixel = args["mm-per-pixel"].as<double>();
  if (input.mm_per_pixel && !(*input.mm_per_pixel > 0.0 && *input.mm_per_pixel <= 1.0)) {
    throw UsageError("--mm-per-pixel must be in (0, 1]");
  }
  if (args.count("scale-presses") != args.count("scale-distance-mm")) {
    throw UsageError("--scale-presses and --scale-distance-mm go together");
  }
  if (args.count("scale-presses")) {
    if (args.count("mm-per-pixel")) {
      throw UsageError("give the scale once: --mm-per-pixel or --scale-presses");
    }
    const auto paths = args["scale-presses"].as<std::vector<std::string>>();
    if (paths.size() != 2) throw UsageError("--scale-presses takes exactly two frames");
    const norm2tex::NamedFrame a = loadFrame(paths[0], size), b = loadFrame(paths[1], size);
    // The mean no-contact frame, as the calibration takes it.
    cv::Mat3f sum(input.backgrounds.front().image.size(), cv::Vec3f(0, 0, 0));
    for (const norm2tex::NamedFrame& frame : input.backgrounds) {
      if (frame.image.size() != sum.size()) break;  // the calibration names the odd frame
      cv::Mat3f f;
      frame.image.convertTo(f, CV_32F);
      sum += f;
    }
    cv::Mat3b background;
    cv::Mat3f(sum / static_cast<double>(input.backgrounds.size())).convertTo(background, CV_8U);
    const norm2tex::PressScale scale = norm2tex::measureScaleFromTwoPresses(
        background, a.image, a.name, b.image, b.name, args["scale-distance-mm"].as<double>());
    std::printf("scale from the two presses: %.1f px apart, %.5f mm/px\n", scale.distance_px,
                scale.mm_per_pixel);
    if (!(scale.mm_per_pixel <= 1.0)) {
      throw Error("the scale presses give " + std::to_string(scale.mm_per_pixel) +
                  " mm/px, more than 1: check --scale-distance-mm");
    }
    input.mm_per_pixel = scale.mm_per_pixel;
  }
  if (args.count("labels")) {
    input.labels = loadLabels(args["labels"].as<std::string>(), input.presses);
  }
  norm2tex::CalibrationOptions options;
  options.holdout_fraction = valueOr(args, "holdout", options.holdout_fraction);

  if (judging) {
    const std::string sensor = args["judge"].as<std::string>();
    const norm2tex::CalibrationResult result =
        norm2tex::judgeSensor(norm2tex::loadSensorModel(sensor), input);
    reportOn(args, json_path, result, input, start, sensor + ": judged");
    return 0;
  }
  const norm2tex::SensorModel base = baseModel(args, input.backgrounds.front().image.size());
  const norm2tex::CalibrationResult result = norm2tex::calibrateSensor(base, input, options);

  // The background goes beside the yaml, referred to by a relative name.
  const std::filesystem::path yaml_path(output);
  const std::string background_name = yaml_path.stem().string() + "_background.png";
  norm2tex::writeImage((yaml_path.parent_path() / background_name).string(), result.background);
  norm2tex::SensorModel model = result.model;
  model.background_image = background_name;
  norm2tex::saveSensorModel(model, output);
  reportOn(args, json_path, result, input, start, output + ": calibrated");
  for (const std::string& line : norm2tex::describeScaleSearch(result.fit)) {
    std::printf("  %s\n", line.c_str());
  }
  warnAboutFittedScale(result.fit);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const norm2tex::cli::Program program = makeProgram();
  return program.main(argc, argv, [&](int argc, char** argv) { return run(program, argc, argv); });
}
