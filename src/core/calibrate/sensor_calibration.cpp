#include "norm2tex/calibrate/sensor_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <set>
#include <sstream>
#include <string>

#include <opencv2/core/utility.hpp>

#include "norm2tex/calibrate/background_noise.hpp"
#include "norm2tex/calibrate/ball_press.hpp"
#include "norm2tex/calibrate/press_refinement.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/render/digit_shader.hpp"

namespace norm2tex {
namespace {

constexpr double kDriftRegionRadii = 2.2;

std::string sizeText(const cv::Mat& image) {
  return std::to_string(image.cols) + " x " + std::to_string(image.rows) +
         (image.cols > image.rows ? " (landscape)" : " (portrait)");
}

void checkFrame(const SensorModel& base, const NamedFrame& frame, const char* role) {
  if (frame.image.empty()) throw Error(std::string(role) + " '" + frame.name + "' is empty");
  if (frame.image.size() == base.imageSize()) return;
  const bool portrait = base.rows > base.cols;
  if ((frame.image.rows > frame.image.cols) != portrait && frame.image.rows != frame.image.cols) {
    throw Error(std::string(role) + " '" + frame.name + "' is " + sizeText(frame.image) +
                " but the sensor's frames are " + std::to_string(base.cols) + " x " +
                std::to_string(base.rows) + (portrait ? " (portrait)" : " (landscape)") +
                "; rotate it the way your driver publishes frames");
  }
  throw Error(std::string(role) + " '" + frame.name + "' is " + sizeText(frame.image) +
              " but the sensor's frames (and the first background) are " +
              std::to_string(base.cols) + " x " + std::to_string(base.rows));
}

cv::Mat3f meanBackground(const std::vector<NamedFrame>& backgrounds) {
  cv::Mat3f sum(backgrounds[0].image.size(), cv::Vec3f(0, 0, 0));
  for (const NamedFrame& frame : backgrounds) {
    cv::Mat3f f;
    frame.image.convertTo(f, CV_32F);
    sum += f;
  }
  return sum / static_cast<double>(backgrounds.size());
}

// Removes a global per-channel offset (lighting drift between the background and the press):
// the median difference of the pixels far from the press.
void removeDrift(PressObservation& press) {
  const double far = kDriftRegionRadii * press.circle.radius_px;
  std::vector<float> values[3];
  for (int r = 0; r < press.diff.rows; ++r) {
    for (int c = 0; c < press.diff.cols; ++c) {
      const double dx = c - press.circle.centre_px.x, dy = r - press.circle.centre_px.y;
      if (dx * dx + dy * dy < far * far) continue;
      for (int k = 0; k < 3; ++k) values[k].push_back(press.diff(r, c)[k]);
    }
  }
  if (values[0].size() < 100) return;  // the press fills the frame: nothing to compare with
  cv::Vec3f offset;
  for (int k = 0; k < 3; ++k) {
    std::nth_element(values[k].begin(), values[k].begin() + values[k].size() / 2, values[k].end());
    offset[k] = values[k][values[k].size() / 2];
  }
  press.diff -= cv::Scalar(offset[0], offset[1], offset[2]);
}

// A press's render at the fitted model against its real frame (the frame as captured).
PressFrameComparison compareFrames(const PressObservation& press, const cv::Mat3b& real_frame,
                                   const cv::Mat3b& background, const cv::Mat3f& simulated_diff,
                                   const SensorModel& model, const PressGeometry& geometry,
                                   double ball_radius_mm) {
  PressFrameComparison comparison;
  comparison.name = press.name;
  comparison.circle = press.circle;
  comparison.contact_radius_px = press.circle.radius_px * geometry.radius_factor;
  comparison.depth_mm =
      ballPressDepthMm(comparison.contact_radius_px * model.mm_per_pixel, ball_radius_mm);
  const cv::Mat1b contact =
      contactDiscMask(real_frame.size(), press.circle.centre_px, comparison.contact_radius_px);
  comparison.similarity =
      compareImages(renderedPressFrame(background, simulated_diff), real_frame, contact);
  comparison.bare_background = compareImages(background, real_frame, contact);
  return comparison;
}


// What calibrating and judging check first (`min_presses` differs).
void checkInput(const SensorModel& base, const CalibrationInput& input, int min_presses,
                const char* what) {
  validate(base);
  if (input.backgrounds.empty()) {
    throw Error(std::string(what) + " needs at least one background frame");
  }
  if (static_cast<int>(input.presses.size()) < min_presses) {
    throw Error(std::string(what) + " needs at least " + std::to_string(min_presses) +
                " ball press" + (min_presses > 1 ? "es" : "") +
                (min_presses == kMinCalibrationPresses ? " (3 to fit, 1 to hold out)" : "") +
                "; got " + std::to_string(input.presses.size()));
  }
  if (!(input.ball_diameter_mm > 0.0 && input.ball_diameter_mm <= 100.0)) {
    std::ostringstream message;
    message << "ball diameter = " << input.ball_diameter_mm
            << " mm is out of range; valid: (0, 100]";
    throw Error(message.str());
  }
  if (!input.labels.empty() && input.labels.size() != input.presses.size()) {
    throw Error("labels: " + std::to_string(input.labels.size()) + " given for " +
                std::to_string(input.presses.size()) + " presses; give one per press or none");
  }
  for (const NamedFrame& frame : input.backgrounds) checkFrame(base, frame, "background");
  for (const NamedFrame& frame : input.presses) checkFrame(base, frame, "press");
}

// Press i's observation: its difference to the mean background, its circle (labelled or
// detected), its lighting drift removed. Marks it in `labelled` when its circle was given.
PressObservation observePress(const CalibrationInput& input, int i, const cv::Mat3f& background,
                              std::set<std::string>& labelled) {
  PressObservation press;
  press.name = input.presses[i].name;
  input.presses[i].image.convertTo(press.diff, CV_32F);
  press.diff -= background;
  const bool has_label = !input.labels.empty() && input.labels[i];
  press.circle = has_label ? *input.labels[i] : detectPress(press.diff, press.name);
  if (has_label) labelled.insert(press.name);
  removeDrift(press);
  return press;
}

// Every unlabelled press's circle refined against `model` (geometry only), each starting from
// its circle times `radius_factor`.
void refineCircles(const SensorModel& model, double radius_factor, double ball_radius_mm,
                   const std::set<std::string>& labelled,
                   std::initializer_list<std::vector<PressObservation>*> sets) {
  const DigitShader shader(model, cv::Mat3b(model.imageSize(), cv::Vec3b(0, 0, 0)),
                           BackgroundSource::kCaptured);
  for (std::vector<PressObservation>* set : sets) {
    for (PressObservation& press : *set) {
      if (labelled.count(press.name)) continue;
      PressCircle start = press.circle;
      start.radius_px *= radius_factor;
      press.circle = refinePressCircle(shader, model, press, start, ball_radius_mm);
    }
  }
}

// Every press rendered by the shader itself at result.model and result.fit.geometry: the
// held-out ones judge the model (held_out, its simulated differences and radii); every press's
// frame is compared with its real one. Presses on all cores, each into its own slot
// (DigitShader keeps per-thread scratch).
void renderAndCompare(const CalibrationInput& input, std::vector<PressObservation> held_out,
                      const std::vector<PressObservation>& training,
                      const std::vector<int>& held_out_index,
                      const std::vector<int>& training_index,
                      const std::set<std::string>& labelled, double ball_radius_mm,
                      CalibrationResult& result) {
  const DigitShader shader(result.model, result.background, BackgroundSource::kCaptured);
  const int held_out_jobs = static_cast<int>(held_out.size());
  const int press_count = held_out_jobs + static_cast<int>(training.size());
  result.held_out_simulated.resize(held_out.size());
  result.held_out_frames.resize(held_out.size());
  result.training_frames.resize(training.size());
  std::mutex error_mutex;
  std::string error;
  cv::parallel_for_(cv::Range(0, press_count), [&](const cv::Range& range) {
    for (int job = range.start; job < range.end; ++job) {
      const bool is_held_out = job < held_out_jobs;
      const int i = is_held_out ? job : job - held_out_jobs;
      const PressObservation& press = is_held_out ? held_out[i] : training[i];
      const int index = is_held_out ? held_out_index[i] : training_index[i];
      try {
        const cv::Mat3f simulated = shader.shadingDifference(
            simulatedPressGel(result.model, press.circle, result.fit.geometry, ball_radius_mm));
        PressFrameComparison comparison =
            compareFrames(press, input.presses[index].image, result.background, simulated,
                          result.model, result.fit.geometry, ball_radius_mm);
        comparison.index = index;
        comparison.held_out = is_held_out;
        comparison.labelled = labelled.count(press.name) > 0;
        if (is_held_out) result.held_out_simulated[i] = simulated;
        (is_held_out ? result.held_out_frames[i] : result.training_frames[i]) =
            std::move(comparison);
      } catch (const std::exception& e) {
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (error.empty()) error = e.what();
      }
    }
  });
  if (!error.empty()) throw Error(error);
  for (const PressObservation& press : held_out) {
    result.held_out_radii_px.push_back(press.circle.radius_px * result.fit.geometry.radius_factor);
  }
  result.held_out_presses = std::move(held_out);
  result.held_out =
      compareWithReal(result.held_out_presses, result.held_out_simulated, result.held_out_radii_px);
}

}  // namespace

namespace {

// The input with a marker gel's dots filled in from their surroundings, in every frame, so the
// shading is fitted and judged on the gel alone; `markers`: the dots found on the mean
// background (none on a DIGIT: the input is returned as it is).
CalibrationInput markerFreeInput(const CalibrationInput& input, DetectedMarkers& markers) {
  cv::Mat3b background;
  meanBackground(input.backgrounds).convertTo(background, CV_8U);
  markers = detectMarkers(background);
  if (!markers.found()) return input;
  // Divided by the light each dot lets through, measured on the background; cores filled in.
  const MarkerRemoval removal(background, markers);
  CalibrationInput clean = input;
  for (NamedFrame& frame : clean.backgrounds) frame.image = removal.apply(frame.image);
  for (NamedFrame& frame : clean.presses) frame.image = removal.apply(frame.image);
  return clean;
}

}  // namespace

CalibrationResult calibrateSensor(const SensorModel& base, const CalibrationInput& raw_input,
                                  const CalibrationOptions& options) {
  checkInput(base, raw_input, kMinCalibrationPresses, "calibration");
  DetectedMarkers markers;
  const CalibrationInput input = markerFreeInput(raw_input, markers);
  if (!(options.holdout_fraction > 0.0 && options.holdout_fraction < 1.0)) {
    throw Error("holdout fraction must be in (0, 1)");
  }

  CalibrationResult result;
  const cv::Mat3f background = meanBackground(input.backgrounds);
  background.convertTo(result.background, CV_8U);

  // Contact circles and drift-corrected differences.
  std::vector<PressObservation> training, held_out;
  std::vector<int> training_index, held_out_index;  // each press's place in the input
  std::set<std::string> labelled;  // presses whose circle the user gave: never refined
  const int n = static_cast<int>(input.presses.size());
  const int held_out_count =
      std::clamp(static_cast<int>(std::lround(options.holdout_fraction * n)), 1, n - 3);
  for (int i = 0; i < n; ++i) {
    PressObservation press = observePress(input, i, background, labelled);
    // Spread the held-out presses evenly over the set: press i is held out when the running
    // count floor((i + 1) k / n) steps up.
    const bool hold = (i + 1) * held_out_count / n > i * held_out_count / n;
    (hold ? held_out : training).push_back(std::move(press));
    (hold ? held_out_index : training_index).push_back(i);
  }

  const double ball_radius_mm = 0.5 * input.ball_diameter_mm;
  // A first fit on the detected circles, then every press's circle refined against it (labelled
  // ones are kept), then the final fit.
  const ShadingFit first =
      fitShadingAndGeometry(base, training, ball_radius_mm, input.mm_per_pixel);
  {
    SensorModel model = base;
    model.mm_per_pixel = first.geometry.mm_per_pixel;
    model.shading = first.shading;
    refineCircles(model, first.geometry.radius_factor, ball_radius_mm, labelled,
                  {&training, &held_out});
  }
  // The refined circles carry the first radius factor: the refit starts from factor 1.
  result.fit = fitShadingAndGeometry(base, training, ball_radius_mm, input.mm_per_pixel,
                                     PressGeometry{first.geometry.mm_per_pixel, 1.0});
  // The scale profile is the first fit's, on the detected circles: the refined ones were fitted
  // at the first scale and would favour it.
  result.fit.scale_search = first.scale_search;
  result.training_presses = static_cast<int>(training.size());

  result.model = base;
  result.model.mm_per_pixel = result.fit.geometry.mm_per_pixel;
  result.model.gel = result.fit.gel;
  result.model.shading = result.fit.shading;
  result.model.noise = measureBackgroundNoise([&] {
    std::vector<cv::Mat3b> frames;
    for (const NamedFrame& frame : input.backgrounds) frames.push_back(frame.image);
    return frames;
  }());
  result.model.background_image.clear();

  // Every press rendered at the fitted geometry: the held-out ones judge the fit; the fitted
  // ones' frames are compared too (one render each, cheap beside the fit).
  renderAndCompare(input, std::move(held_out), training, held_out_index, training_index, labelled,
                   ball_radius_mm, result);
  if (markers.found()) {
    // The layout measured on the background, at the fitted scale; the background kept is the
    // marker-free one (the renderer draws the markers where the gel carries them).
    result.model.markers = markers.options(result.model, result.model.mm_per_pixel);
    result.markers = std::move(markers);
  }
  return result;
}

CalibrationResult judgeSensor(const SensorModel& fitted, const CalibrationInput& raw_input) {
  checkInput(fitted, raw_input, 1, "judging a sensor");
  DetectedMarkers markers;
  const CalibrationInput input = markerFreeInput(raw_input, markers);
  if (input.mm_per_pixel && std::abs(*input.mm_per_pixel - fitted.mm_per_pixel) >
                                1e-9 * fitted.mm_per_pixel) {
    std::ostringstream message;
    message << "the sensor judged was calibrated at " << fitted.mm_per_pixel
            << " mm/px, not the " << *input.mm_per_pixel << " given: leave the scale out";
    throw Error(message.str());
  }
  CalibrationResult result;
  const cv::Mat3f background = meanBackground(input.backgrounds);
  background.convertTo(result.background, CV_8U);
  std::vector<PressObservation> presses;
  std::vector<int> index;
  std::set<std::string> labelled;
  for (int i = 0; i < static_cast<int>(input.presses.size()); ++i) {
    presses.push_back(observePress(input, i, background, labelled));
    index.push_back(i);
  }
  const double ball_radius_mm = 0.5 * input.ball_diameter_mm;
  // The circles found as the calibration finds its held-out presses': refined against the
  // model (geometry only); nothing of the shading is fitted to these presses.
  refineCircles(fitted, 1.0, ball_radius_mm, labelled, {&presses});
  result.model = fitted;
  result.model.background_image.clear();
  result.fit.geometry = PressGeometry{fitted.mm_per_pixel, 1.0};
  result.fit.shading = fitted.shading;
  result.fit.gel = fitted.gel;
  result.training_presses = 0;
  renderAndCompare(input, std::move(presses), {}, index, {}, labelled, ball_radius_mm, result);
  return result;
}

}  // namespace norm2tex
