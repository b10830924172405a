#include "norm2tex/calibrate/texture_match.hpp"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <limits>

#include "norm2tex/common/error.hpp"
#include "norm2tex/mesh/mesh_primitives.hpp"
#include "norm2tex/render/tactile_renderer.hpp"

namespace norm2tex {
namespace {

constexpr double kFaceSideMm = 30.0;  // wider than the imaged 12.8 x 17 mm at any tilt used
constexpr double kFaceThicknessMm = 10.0;
constexpr double kCoversImage = 0.9;  // contact fraction from which the area says nothing
constexpr double kMaxBetaMm = 2.0;    // validate(MaterialConfig)'s bound
constexpr double kRmsFloor = 0.05;    // grey levels: a band below it counts as this (no log 0)
constexpr int kDepthIterations = 12;
constexpr int kBetaIterations = 9;  // within a 2x bracket: to 0.14 %
constexpr double kSlopeStep = 1.25;  // beta's step that measures which way the texture goes
constexpr int kModulusRefinements = 8;
// E* grid (MPa): soft silicone to stiff rubber; the shipped gel's is 0.1.
const double kModulusGrid[] = {0.02, 0.035, 0.06, 0.1, 0.18, 0.32, 0.56, 1.0};

double logRatio(double sim, double real) {
  return std::log(std::max(sim, kRmsFloor) / std::max(real, kRmsFloor));
}

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.3g", value);
  return text;
}

cv::Mat3f difference(const cv::Mat3b& image, const cv::Mat3b& background) {
  cv::Mat3f a, b;
  image.convertTo(a, CV_32F);
  background.convertTo(b, CV_32F);
  return a - b;
}

}  // namespace

// The fit's state: a renderer at the current E*, each frame's matched press, the real bands.
class TextureMatcher::Session {
 public:
  Session(const TextureMatcher& matcher, const std::vector<TextureFrame>& frames)
      : m_(matcher), frames_(frames), face_(sampleFace(matcher.sample_.period_mm)) {
    setModulus(m_.model_.conformity.contact_modulus_mpa);
    // The sensor's own noise floor, for frames with too little free gel to measure it.
    const Eigen::Isometry3d lifted = samplePose(m_.model_, 0.0, -5.0);
    renderer_->setObject(face_);
    no_contact_ = measureNoContactLevel(
        difference(renderer_->render(lifted, m_.options_.noise_seed).image, m_.background_),
        m_.options_.band);
    for (const TextureFrame& frame : frames_) {
      real_.push_back(measureTextureBand(difference(frame.image, m_.background_), no_contact_,
                                         frame.name, m_.options_.band));
    }
    press_mm_.assign(frames_.size(), 0.0);
    tilt_deg_.assign(frames_.size(), m_.options_.tilt_deg);
  }

  void setModulus(double modulus_mpa) {
    SensorModel model = m_.model_;
    model.conformity.contact_modulus_mpa = modulus_mpa;
    // The simulated frames carry the sensor's noise, so their contact is found against the same
    // kind of noise as the real ones' (seeds fixed: deterministic).
    model.noise.on_real_background = true;
    model.background_image.clear();
    renderer_.emplace(model, m_.background_, BackgroundSource::kCaptured);
    modulus_mpa_ = modulus_mpa;
  }
  double modulus() const { return modulus_mpa_; }

  void setBeta(double beta_mm) {
    renderer_->setObject(face_, m_.sample_.atlas, beta_mm);
    beta_mm_ = beta_mm;
  }

  // Per frame: the press whose detected contact area equals the real one (bisection; the area
  // grows with the depth of a tilted face). A contact over the whole image gives no area to
  // match: a parallel face at the gel law's depth for the given force.
  void matchPresses() {
    const double height_mm = m_.model_.gelHeightMm();
    for (size_t i = 0; i < frames_.size(); ++i) {
      const std::optional<double>& force = frames_[i].normal_force_n;
      if (real_[i].contact_fraction >= kCoversImage) {
        if (!force) {
          throw Error("frame '" + frames_[i].name + "': the contact covers " +
                      std::to_string(cvRound(100.0 * real_[i].contact_fraction)) +
                      " % of the image, so its area cannot tell how hard the sample was " +
                      "pressed; give the frames' forces, or press the sample slightly tilted so " +
                      "that part of the gel stays free");
        }
        tilt_deg_[i] = 0.0;
        press_mm_[i] = renderer_->gelLaw().indentation(*force) * 1e3;
        continue;
      }
      tilt_deg_[i] = m_.options_.tilt_deg;
      double lo = 0.005;
      double hi = height_mm * std::tan(tilt_deg_[i] * M_PI / 180.0);  // reaches the top
      for (int k = 0; k < kDepthIterations; ++k) {
        const double mid = 0.5 * (lo + hi);
        (simulatedContactPixels(i, mid) < real_[i].contact_pixels ? lo : hi) = mid;
      }
      press_mm_[i] = 0.5 * (lo + hi);
    }
  }

  // The simulated band of frame i at its matched press (its image kept when `keep`).
  TextureBand simulate(size_t i, FrameMatch* keep = nullptr) {
    const TactileFrame& frame = render(i, press_mm_[i]);
    try {
      TextureBand band = measureTextureBand(difference(frame.image, m_.background_),
                                            no_contact_, frames_[i].name, m_.options_.band);
      if (keep) {
        keep->sim_image = frame.image.clone();
        // Without conformity the renderer takes no force: the gel law's at the deepest press.
        keep->force_n = frame.conformity ? frame.conformity->normal_force_n
                        : forceOf(i)     ? *forceOf(i)
                                         : renderer_->gelLaw().force(press_mm_[i] * 1e-3);
        const double area_mm2 = cv::countNonZero(frame.contact_mask) * m_.model_.mm_per_pixel *
                                m_.model_.mm_per_pixel;
        keep->mean_pressure_mpa = area_mm2 > 0 ? keep->force_n / area_mm2 : 0.0;
      }
      return band;
    } catch (const Error& e) {
      // While beta is searched, a texture too faint to show a contact shows no texture either.
      if (!keep) return TextureBand();
      throw Error(std::string("the simulated press matched to ") + e.what());
    }
  }

  // Mean and RMS over the frames of ln(sim / real) at the current beta.
  cv::Vec2d logRatios() {
    double sum = 0.0, sum2 = 0.0;
    for (size_t i = 0; i < frames_.size(); ++i) {
      const double r = logRatio(simulate(i).rms, real_[i].rms);
      sum += r, sum2 += r * r;
    }
    const double n = static_cast<double>(frames_.size());
    return {sum / n, std::sqrt(sum2 / n)};
  }

  // The beta where the mean log ratio crosses 0, nearest the current one: bracketed by steps of
  // 2x from it towards the root, then bisected on ln beta. Which way is towards the root depends
  // on the local slope, measured first: a relief the gel follows fully shows more texture the
  // deeper it is, but one it follows only on its crests (a light press, or short wavelengths
  // under the coating, whose p* grows with the depth) shows less, since the gel touches fewer,
  // narrower crests. Not globally monotone either way (grooves much deeper than the press leave
  // the gel untouched), so a search over the whole range could settle on a far root. Leaves the
  // session at the result; returns {beta, misfit}.
  cv::Vec2d fitBeta(double lo, double hi, bool* at_bound) {
    double a = std::clamp(beta_mm_, lo, hi);
    *at_bound = false;
    const double probe = a < hi ? std::min(a * kSlopeStep, hi) : std::max(a / kSlopeStep, lo);
    setBeta(probe);
    const double probe_ratio = logRatios()[0];
    setBeta(a);
    cv::Vec2d ratios = logRatios();
    // ln(sim / real) grows with beta here (more texture for a deeper relief) or falls.
    const bool grows = (probe_ratio - ratios[0]) * (probe - a) >= 0.0;
    const bool up = (ratios[0] < 0.0) == grows;
    const bool start_below = ratios[0] < 0.0;
    double b = a;
    for (;;) {
      const double next = up ? std::min(b * 2.0, hi) : std::max(b * 0.5, lo);
      if (next == b) {  // at the range's end, still on the same side
        *at_bound = true;
        return {b, ratios[1]};
      }
      a = b, b = next;
      setBeta(b);
      ratios = logRatios();
      if ((ratios[0] < 0.0) != start_below) break;
    }
    // `a` is on the start's side of the root, `b` past it.
    double on_start_side = std::log(a), past = std::log(b);
    for (int k = 0; k < kBetaIterations; ++k) {
      const double mid = 0.5 * (on_start_side + past);
      setBeta(std::exp(mid));
      ((logRatios()[0] < 0.0) == start_below ? on_start_side : past) = mid;
    }
    setBeta(std::exp(0.5 * (on_start_side + past)));
    return {beta_mm_, logRatios()[1]};
  }

  // E* when the frames can show it: misfit at each grid modulus (beta refitted), golden-section
  // refinement around the best, kept only if the misfit rises clearly on both sides. Leaves the
  // session at the modulus used and `fit` ({beta, misfit}) at it; returns what was done, why.
  std::string fitModulus(double lo, double hi, cv::Vec2d& fit, bool& at_bound) {
    const std::string keep = "E* kept at the sensor's " + number(modulus_mpa_) + " MPa: ";
    if (!m_.model_.conformity.enabled) {
      return keep + "conformity is off in the sensor yaml, so E* plays no part";
    }
    if (!m_.options_.fit_contact_modulus) return keep + "not asked to fit it";
    if (!frames_.front().normal_force_n) {
      return keep + "not identifiable without the frames' forces (the gel law's forces follow " +
             "the press depth, not the sample)";
    }
    if (frames_.size() < 3) return keep + "not identifiable from fewer than 3 frames";
    double p_min = std::numeric_limits<double>::infinity(), p_max = 0.0;
    for (size_t i = 0; i < frames_.size(); ++i) {
      FrameMatch probe;
      simulate(i, &probe);
      p_min = std::min(p_min, probe.mean_pressure_mpa);
      p_max = std::max(p_max, probe.mean_pressure_mpa);
    }
    if (!(p_max >= m_.options_.min_pressure_ratio * p_min)) {
      return keep + "not identifiable: the frames' mean pressures span only " +
             number(p_max / p_min) + "x (need >= " + number(m_.options_.min_pressure_ratio) +
             "x, light to firm presses) for the texture's growth with pressure to show p*";
    }
    const double start = modulus_mpa_;
    const cv::Vec2d start_fit = fit;
    const bool start_bound = at_bound;
    std::vector<double> misfits;
    for (double e : kModulusGrid) {
      setModulus(e);
      bool bound = false;
      misfits.push_back(fitBeta(lo, hi, &bound)[1]);
    }
    const size_t n = misfits.size();
    const size_t best = std::min_element(misfits.begin(), misfits.end()) - misfits.begin();
    const auto restore = [&](const std::string& why) {
      setModulus(start);
      setBeta(start_fit[0]);
      fit = start_fit;
      at_bound = start_bound;
      return keep + why;
    };
    if (best == 0 || best + 1 == n) {
      return restore("not identifiable: the misfit is least at the end of the searched 0.02-1 "
                     "MPa; the pressures lie all below or all above p*");
    }
    const double margin = std::max(0.02, 0.5 * misfits[best]);
    if (misfits[best - 1] < misfits[best] + margin || misfits[best + 1] < misfits[best] + margin) {
      return restore("not identifiable: the misfit changes by less than " + number(margin) +
                     " over a factor ~1.8 of E* (the band RMS does not bend enough with force)");
    }
    // Golden section on ln E* between the best's neighbours.
    double a = std::log(kModulusGrid[best - 1]), b = std::log(kModulusGrid[best + 1]);
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    const auto misfitAt = [&](double log_e) {
      setModulus(std::exp(log_e));
      bool bound = false;
      return fitBeta(lo, hi, &bound)[1];
    };
    double c = b - g * (b - a), d = a + g * (b - a);
    double fc = misfitAt(c), fd = misfitAt(d);
    for (int k = 0; k < kModulusRefinements; ++k) {
      if (fc < fd) {
        b = d, d = c, fd = fc, c = b - g * (b - a), fc = misfitAt(c);
      } else {
        a = c, c = d, fc = fd, d = a + g * (b - a), fd = misfitAt(d);
      }
    }
    setModulus(std::exp(0.5 * (a + b)));
    fit = fitBeta(lo, hi, &at_bound);
    matchPresses();
    fit = fitBeta(lo, hi, &at_bound);
    return "E* fitted: " + number(modulus_mpa_) + " MPa (misfit " + number(misfits[best - 1]) +
           " and " + number(misfits[best + 1]) + " at the grid's " + number(kModulusGrid[best - 1]) +
           " and " + number(kModulusGrid[best + 1]) + " MPa)";
  }

  const std::vector<TextureBand>& real() const { return real_; }
  double pressMm(size_t i) const { return press_mm_[i]; }
  double tiltDeg(size_t i) const { return tilt_deg_[i]; }

 private:
  std::optional<double> forceOf(size_t i) const { return frames_[i].normal_force_n; }

  const TactileFrame& render(size_t i, double press_mm) {
    return renderer_->render(samplePose(m_.model_, tilt_deg_[i], press_mm),
                             m_.options_.noise_seed + static_cast<std::int64_t>(i), forceOf(i));
  }

  int simulatedContactPixels(size_t i, double press_mm) {
    try {
      return measureTextureBand(difference(render(i, press_mm).image, m_.background_),
                                no_contact_, frames_[i].name, m_.options_.band)
          .contact_pixels;
    } catch (const Error&) {
      return 0;  // too shallow to show a contact: deeper
    }
  }

  const TextureMatcher& m_;
  const std::vector<TextureFrame>& frames_;
  std::shared_ptr<const TexturedMesh> face_;
  std::optional<TactileRenderer> renderer_;
  double modulus_mpa_ = 0.0, beta_mm_ = 0.0;
  NoContactLevel no_contact_;
  std::vector<TextureBand> real_;
  std::vector<double> press_mm_, tilt_deg_;
};

TextureMatcher::TextureMatcher(SensorModel model, cv::Mat3b background, TextureSample sample,
                               TextureMatchOptions options)
    : model_(std::move(model)),
      background_(std::move(background)),
      sample_(std::move(sample)),
      options_(std::move(options)) {
  validate(model_);
  if (background_.size() != model_.imageSize()) {
    throw Error("the background is " + std::to_string(background_.cols) + " x " +
                std::to_string(background_.rows) + " but the sensor's image is " +
                std::to_string(model_.cols) + " x " + std::to_string(model_.rows) +
                "; give the sensor yaml of the DIGIT that took the frames");
  }
  if (!sample_.atlas || !(sample_.beta_mm > 0.0) || !(sample_.period_mm > 0.0)) {
    throw Error("texture match: the sample needs a texture, beta_mm > 0 and period_mm > 0");
  }
  if (!(options_.tilt_deg >= 0.5 && options_.tilt_deg <= 20.0)) {
    throw Error("texture match: tilt_deg " + std::to_string(options_.tilt_deg) +
                " is outside [0.5, 20] degrees");
  }
  if (!(options_.beta_range_factor > 1.0)) {
    throw Error("texture match: beta_range_factor must be > 1");
  }
}

std::shared_ptr<const TexturedMesh> TextureMatcher::sampleFace(double period_mm) {
  return std::make_shared<const TexturedMesh>(
      makeBox(Eigen::Vector3d(kFaceSideMm, kFaceSideMm, kFaceThicknessMm) * 1e-3,
              period_mm * 1e-3));
}

Eigen::Isometry3d TextureMatcher::samplePose(const SensorModel& model, double tilt_deg,
                                             double press_mm) {
  // Rotated by -tilt about x, the bottom face's plane is z(y) = z0 + tan(-tilt) (y - y0): it
  // falls towards +y (the image's bottom). Lift it so that z = -press_mm at the bottom edge.
  const double a = -tilt_deg * M_PI / 180.0, half = 0.5 * kFaceThicknessMm;
  const double y0 = half * std::sin(a), z0 = -half * std::cos(a);
  const double z_edge = z0 + std::tan(a) * (0.5 * model.gelHeightMm() - y0);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(0.0, 0.0, (-press_mm - z_edge) * 1e-3);
  return pose;
}

TextureMatchResult TextureMatcher::fit(const std::vector<TextureFrame>& frames) const {
  if (static_cast<int>(frames.size()) < kMinTextureMatchFrames) {
    throw Error("texture match needs at least " + std::to_string(kMinTextureMatchFrames) +
                " frames (3 or more at different forces recommended); got " +
                std::to_string(frames.size()));
  }
  size_t with_force = 0;
  for (const TextureFrame& frame : frames) {
    if (frame.image.size() != background_.size()) {
      throw Error("frame '" + frame.name + "' is " + std::to_string(frame.image.cols) + " x " +
                  std::to_string(frame.image.rows) + " but the background is " +
                  std::to_string(background_.cols) + " x " + std::to_string(background_.rows));
    }
    if (frame.normal_force_n) {
      ++with_force;
      if (!std::isfinite(*frame.normal_force_n) || !(*frame.normal_force_n > 0.0)) {
        throw Error("frame '" + frame.name + "': force " + std::to_string(*frame.normal_force_n) +
                    " N is not valid; a press's normal force is finite and > 0 N");
      }
    }
  }
  if (with_force != 0 && with_force != frames.size()) {
    throw Error("forces are given for " + std::to_string(with_force) + " of " +
                std::to_string(frames.size()) + " frames; give one for every frame or none");
  }

  Session session(*this, frames);
  TextureMatchResult result;
  result.conformity = model_.conformity.enabled;
  result.start_beta_mm = sample_.beta_mm;
  const double lo = std::max(sample_.beta_mm / options_.beta_range_factor, 1e-4);
  const double hi = std::min(sample_.beta_mm * options_.beta_range_factor, kMaxBetaMm);

  // Two passes: the press is matched by detected area, which the texture shifts a little.
  session.setBeta(sample_.beta_mm);
  session.matchPresses();
  result.start_misfit = session.logRatios()[1];
  cv::Vec2d fit = session.fitBeta(lo, hi, &result.beta_at_bound);
  session.matchPresses();
  fit = session.fitBeta(lo, hi, &result.beta_at_bound);

  result.contact_modulus_note = session.fitModulus(lo, hi, fit, result.beta_at_bound);
  result.contact_modulus_fitted = session.modulus() != model_.conformity.contact_modulus_mpa;
  if (!result.contact_modulus_fitted && fit[1] > result.start_misfit) {
    // Where the mean log ratio crosses 0 need not lower the misfit: frames whose texture is
    // under their noise (fine relief the gel's coating holds back) put it anywhere. Fitting
    // then says nothing, and the material's own beta is the honest answer.
    session.setBeta(sample_.beta_mm);
    fit = {sample_.beta_mm, session.logRatios()[1]};
    result.beta_at_bound = false;
    result.beta_kept = true;
    result.warnings.push_back(
        "beta kept at the material's " + number(sample_.beta_mm) + " mm: no other depth in " +
        number(lo) + "-" + number(hi) + " mm matches the frames better (their texture is too " +
        "faint to pin it: press harder, or the gel holds this relief back)");
  }
  result.beta_mm = fit[0];
  result.misfit = fit[1];
  result.contact_modulus_mpa = session.modulus();
  if (result.beta_at_bound) {
    result.warnings.push_back(
        "beta is at the end of the searched range (" + std::to_string(lo) + "-" +
        std::to_string(hi) + " mm): the frames show " +
        (fit[0] <= lo ? "less texture than the material at its least" : "more texture than the "
                                                                        "material at its most"));
  }
  for (size_t i = 0; i < frames.size(); ++i) {
    FrameMatch match;
    match.name = frames[i].name;
    match.force_given = frames[i].normal_force_n.has_value();
    match.press_mm = session.pressMm(i);
    match.tilt_deg = session.tiltDeg(i);
    match.real = session.real()[i];
    match.real_image = frames[i].image;
    match.sim = session.simulate(i, &match);
    if (match.real.rms < match.real.noise_rms) {
      result.warnings.push_back("frame '" + match.name + "': its texture band (" +
                                std::to_string(match.real.rms) +
                                " grey levels) is below its noise floor; it pins beta weakly");
    }
    if (!match.real.noise_from_frame) {
      result.warnings.push_back("frame '" + match.name + "': too little free gel to measure " +
                                "its noise; the sensor yaml's noise is assumed");
    }
    result.frames.push_back(std::move(match));
  }
  return result;
}

}  // namespace norm2tex
