// norm2tex_gripper_sweep: squeezes each scene's object harder and harder and plots what the
// gels feel against the configured gel law (the physics figure of docs/physics.md).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "cli_arguments.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/common/image_io.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/sim/contact_patch.hpp"
#include "norm2tex/sim/gripper_sim.hpp"
#include "package_paths.hpp"

namespace {

namespace po = norm2tex::cli::po;

norm2tex::cli::Program makeProgram() {
  norm2tex::cli::Program program(
      "norm2tex_gripper_sweep",
      "norm2tex_gripper_sweep [--scene SCENE.yaml]... -o PLOT.png [--csv OUT.csv]\n"
      "                              [--friction MU]",
      "Closes the gripper on each scene's object from its grasp opening in steps of 0.0025\n"
      "(300 ticks each) until the left gel carries 95 % of gripper.max_force_n, and plots force\n"
      "against indentation (with the gel law) and contact area against the command.");
  program.add()  //
      ("scene", po::value<std::vector<std::string>>()->composing()->value_name("SCENE.yaml"),
       "A scene yaml, repeatable (default: config/scenes/cube.yaml and sphere.yaml).")  //
      ("output,o", po::value<std::string>()->value_name("PLOT.png"), "The plot.")       //
      ("csv", po::value<std::string>()->value_name("OUT.csv"), "The raw rows.")         //
      ("friction", po::value<double>()->value_name("MU"),
       "Overrides every scene's object.friction.");
  return program;
}

constexpr double kOpeningStep = 0.0025;
constexpr int kSettleTicks = 300;
constexpr double kForceFraction = 0.95;

struct Row {
  double opening, gap_mm, force_n, penetration_mm, area_mm2, law_force_n;
};

struct Scene {
  std::string name;
  std::vector<Row> rows;
};

std::vector<Row> sweep(const norm2tex::GripperSimConfig& config,
                       const norm2tex::SensorModel& sensor) {
  norm2tex::GripperSim sim(config);
  norm2tex::ContactPatchMeter meter(sensor);
  const norm2tex::GelLaw& law = sim.config().gel_law;
  std::vector<Row> rows;
  for (double opening = sim.reset(1, 0.0).grasp_opening;; opening -= kOpeningStep) {
    opening = std::max(opening, 0.0);
    sim.setOpening(opening);
    sim.step(kSettleTicks);
    if (sim.dropped()) break;
    const norm2tex::GelContactState& gel = sim.contact(norm2tex::Finger::kLeft);
    const double area_m2 = meter.measure(sim.object().mesh, gel.object_in_gel).area_m2;
    rows.push_back({opening, sim.gapForOpening(opening) * 1e3, gel.normal_force_n,
                    gel.penetration_m * 1e3, area_m2 * 1e6, law.force(gel.penetration_m)});
    if (gel.normal_force_n >= kForceFraction * config.gripper.max_force_n || opening <= 0.0) break;
  }
  return rows;
}

// --- Plotting: just enough of a chart library for two panels. ---

const cv::Scalar kBlack(0, 0, 0), kGrey(225, 225, 225), kDarkGrey(110, 110, 110);
const cv::Scalar kPalette[] = {
    {180, 119, 31}, {14, 127, 255}, {44, 160, 44}, {40, 39, 214}, {189, 103, 148}};
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;

void text(cv::Mat3b& image, const std::string& s, cv::Point at, double scale = 0.45,
          const cv::Scalar& colour = kBlack, int thickness = 1) {
  cv::putText(image, s, at, kFont, scale, colour, thickness, cv::LINE_AA);
}

cv::Size textSize(const std::string& s, double scale = 0.45, int thickness = 1) {
  int baseline = 0;
  return cv::getTextSize(s, kFont, scale, thickness, &baseline);
}

/// 1, 2 or 5 times a power of ten, giving about five ticks over `span`.
double niceStep(double span) {
  const double raw = span / 5.0, magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 5.0}) {
    if (m * magnitude >= raw) return m * magnitude;
  }
  return 10.0 * magnitude;
}

std::string label(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%g", std::abs(value) < 1e-12 ? 0.0 : value);
  return buffer;
}

/// A plot area with data ranges; x0 > x1 flips the x axis.
struct Axes {
  cv::Rect area;
  double x0, x1, y0, y1;
  cv::Point map(double x, double y) const {
    return {
        area.x + static_cast<int>(std::lround((x - x0) / (x1 - x0) * area.width)),
        area.y + area.height - static_cast<int>(std::lround((y - y0) / (y1 - y0) * area.height))};
  }
};

void drawAxes(cv::Mat3b& image, const Axes& axes, const std::string& title,
              const std::string& x_label, const std::string& y_label) {
  const cv::Rect& r = axes.area;
  const double x_step = niceStep(std::abs(axes.x1 - axes.x0)), y_step = niceStep(axes.y1 - axes.y0);
  const double x_lo = std::min(axes.x0, axes.x1), x_hi = std::max(axes.x0, axes.x1);
  for (double x = std::ceil(x_lo / x_step - 1e-9) * x_step; x <= x_hi + 1e-9; x += x_step) {
    const int px = axes.map(x, axes.y0).x;
    cv::line(image, {px, r.y}, {px, r.y + r.height}, kGrey);
    cv::line(image, {px, r.y + r.height}, {px, r.y + r.height + 5}, kBlack);
    const std::string s = label(std::round(x / x_step) * x_step);
    text(image, s, {px - textSize(s).width / 2, r.y + r.height + 20});
  }
  for (double y = std::ceil(axes.y0 / y_step - 1e-9) * y_step; y <= axes.y1 + 1e-9; y += y_step) {
    const int py = axes.map(axes.x0, y).y;
    cv::line(image, {r.x, py}, {r.x + r.width, py}, kGrey);
    cv::line(image, {r.x - 5, py}, {r.x, py}, kBlack);
    const std::string s = label(std::round(y / y_step) * y_step);
    text(image, s, {r.x - 9 - textSize(s).width, py + 5});
  }
  cv::rectangle(image, r, kBlack);
  const cv::Size title_size = textSize(title, 0.6, 2);
  text(image, title, {r.x + (r.width - title_size.width) / 2, r.y - 14}, 0.6, kBlack, 2);
  text(image, x_label, {r.x + (r.width - textSize(x_label, 0.5).width) / 2, r.y + r.height + 44},
       0.5);
  // putText only writes horizontally: draw the y label on a strip and rotate it.
  const cv::Size y_size = textSize(y_label, 0.5);
  cv::Mat3b strip(y_size.height + 8, y_size.width + 4, cv::Vec3b(255, 255, 255));
  text(strip, y_label, {2, y_size.height + 2}, 0.5);
  cv::rotate(strip, strip, cv::ROTATE_90_COUNTERCLOCKWISE);
  strip.copyTo(
      image(cv::Rect(r.x - 62, r.y + (r.height - strip.rows) / 2, strip.cols, strip.rows)));
}

enum class Marker { kDot, kRing, kSquare, kLine };

void marker(cv::Mat3b& image, cv::Point at, Marker kind, const cv::Scalar& colour) {
  if (kind == Marker::kDot) cv::circle(image, at, 3, colour, cv::FILLED, cv::LINE_AA);
  if (kind == Marker::kRing) cv::circle(image, at, 6, colour, 2, cv::LINE_AA);
  if (kind == Marker::kSquare)
    cv::rectangle(image, at - cv::Point(5, 5), at + cv::Point(5, 5), colour, 2);
  if (kind == Marker::kLine)
    cv::line(image, at - cv::Point(12, 0), at + cv::Point(12, 0), colour, 2, cv::LINE_AA);
}

struct LegendEntry {
  std::string name;
  Marker kind;
  cv::Scalar colour;
};

/// A boxed legend whose top-left corner is `at`.
void legend(cv::Mat3b& image, cv::Point at, const std::vector<LegendEntry>& entries) {
  int width = 0;
  for (const LegendEntry& e : entries) width = std::max(width, textSize(e.name).width);
  const cv::Rect box(at.x, at.y, width + 52, static_cast<int>(entries.size()) * 22 + 8);
  cv::rectangle(image, box, cv::Scalar(255, 255, 255), cv::FILLED);
  cv::rectangle(image, box, kDarkGrey);
  for (size_t i = 0; i < entries.size(); ++i) {
    const int y = at.y + 15 + static_cast<int>(i) * 22;
    marker(image, {at.x + 20, y}, entries[i].kind, entries[i].colour);
    text(image, entries[i].name, {at.x + 40, y + 5});
  }
}

cv::Mat3b plot(const std::vector<Scene>& scenes, const norm2tex::GelLaw& law,
               const norm2tex::SensorModel& sensor) {
  cv::Mat3b image(500, 1200, cv::Vec3b(255, 255, 255));
  double max_d = 0.0, max_f = 0.0, max_area = 0.0, min_open = 1.0, max_open = 0.0;
  for (const Scene& scene : scenes) {
    for (const Row& row : scene.rows) {
      max_d = std::max(max_d, row.penetration_mm);
      max_f = std::max(max_f, row.force_n);
      max_area = std::max(max_area, row.area_mm2);
      min_open = std::min(min_open, row.opening);
      max_open = std::max(max_open, row.opening);
    }
  }
  // Left: the law's curve over the swept range (and its last table point).
  const double d_max = 1.05 * std::max(max_d, law.points().back().first * 1e3);
  const Axes force{
      {90, 45, 470, 380}, 0.0, d_max, 0.0, 1.1 * std::max(max_f, law.force(d_max * 1e-3))};
  drawAxes(image, force, "Gel law: force vs indentation", "indentation [mm]", "normal force [N]");
  std::vector<cv::Point> curve;
  for (int i = 0; i <= 200; ++i) {
    const double d = d_max * i / 200.0;
    curve.push_back(force.map(d, law.force(d * 1e-3)));
  }
  cv::polylines(image, curve, false, kBlack, 2, cv::LINE_AA);
  for (const auto& [d, f] : law.points())
    marker(image, force.map(d * 1e3, f), Marker::kSquare, kDarkGrey);
  std::vector<LegendEntry> left{{"gel law", Marker::kLine, kBlack},
                                {"law table points", Marker::kSquare, kDarkGrey}};
  // Right: x runs from wide to narrow so a harder squeeze is to the right in both panels.
  const double pad = 0.05 * std::max(max_open - min_open, 0.01);
  const double open_lo = std::max(min_open - pad, 0.0), area_hi = 1.15 * std::max(max_area, 1.0);
  const Axes area{{690, 45, 470, 380}, max_open + pad, open_lo, 0.0, area_hi};
  drawAxes(image, area, "Contact area vs grip command", "opening command (narrower ->)",
           "contact area [mm^2]");
  // The whole imaged gel: the most contact the sensor can see.
  const double gel_mm2 = sensor.gelWidthMm() * sensor.gelHeightMm();
  for (int x = area.area.x; x < area.area.br().x; x += 12) {
    const int y = area.map(area.x0, gel_mm2).y;
    cv::line(image, {x, y}, {std::min(x + 6, area.area.br().x), y}, kDarkGrey);
  }
  const std::string gel_text = "whole gel " + label(std::round(gel_mm2)) + " mm^2";
  text(image, gel_text,
       {area.area.br().x - textSize(gel_text).width - 6, area.map(area.x0, gel_mm2).y - 8}, 0.45,
       kDarkGrey);
  std::vector<LegendEntry> right;
  for (size_t s = 0; s < scenes.size(); ++s) {
    const cv::Scalar& colour = kPalette[s % std::size(kPalette)];
    // Rings, then dots: scenes often share a stretch of the law curve.
    const Marker kind = s % 2 == 0 ? Marker::kRing : Marker::kDot;
    std::vector<cv::Point> line;
    for (const Row& row : scenes[s].rows) {
      marker(image, force.map(row.penetration_mm, row.force_n), kind, colour);
      line.push_back(area.map(row.opening, row.area_mm2));
    }
    cv::polylines(image, line, false, colour, 2, cv::LINE_AA);
    for (const cv::Point& p : line) marker(image, p, Marker::kDot, colour);
    left.push_back({scenes[s].name + " (sim, left gel)", kind, colour});
    right.push_back({scenes[s].name, Marker::kDot, colour});
  }
  legend(image, {force.area.x + 12, force.area.y + 12}, left);
  legend(image,
         {area.area.x + 12,
          area.area.y + area.area.height - 12 - 22 * static_cast<int>(right.size()) - 8},
         right);
  return image;
}

int run(const norm2tex::cli::Program& program, int argc, char** argv) {
  const po::variables_map args = program.parse(argc, argv);
  const std::string output = norm2tex::cli::valueOr<std::string>(args, "output", "");
  if (output.empty()) throw norm2tex::cli::UsageError("missing -o PLOT.png");
  const std::string config_dir = norm2tex::cli::configDirectory();
  std::vector<std::string> paths =
      norm2tex::cli::valueOr(args, "scene", std::vector<std::string>());
  if (paths.empty()) paths = {config_dir + "/scenes/cube.yaml", config_dir + "/scenes/sphere.yaml"};
  const norm2tex::SensorModel sensor = norm2tex::loadSensorModel(config_dir + "/digit.yaml");

  std::vector<Scene> scenes;
  norm2tex::GelLaw law = norm2tex::GelLaw::taximDefault();
  for (const std::string& path : paths) {
    norm2tex::GripperSimConfig config = norm2tex::loadGripperSimConfig(path);
    norm2tex::setGelFromSensor(sensor, config);
    if (args.count("friction")) config.object.friction = args["friction"].as<double>();
    scenes.push_back({std::filesystem::path(path).stem().string(), sweep(config, sensor)});
    law = config.gel_law;  // the curve drawn is the last scene's law (the scenes share one)

    const std::vector<Row>& rows = scenes.back().rows;
    double max_f = 0.0, max_d = 0.0, worst = 0.0;
    for (const Row& row : rows) {
      max_f = std::max(max_f, row.force_n);
      max_d = std::max(max_d, row.penetration_mm);
      if (row.law_force_n > 0.0)
        worst = std::max(worst, std::abs(row.force_n - row.law_force_n) / row.law_force_n);
    }
    std::printf(
        "%s: %zu points, max force %.2f N, max indentation %.3f mm, "
        "max |F - law(d)| / law(d) %.2g %%\n",
        scenes.back().name.c_str(), rows.size(), max_f, max_d, 100.0 * worst);
  }

  if (args.count("csv")) {
    const std::string csv_path = args["csv"].as<std::string>();
    std::ofstream csv(csv_path);
    csv << "scene,opening,gap_mm,force_n,penetration_mm,area_mm2,law_force_n\n";
    for (const Scene& scene : scenes) {
      for (const Row& r : scene.rows) {
        csv << scene.name << ',' << r.opening << ',' << r.gap_mm << ',' << r.force_n << ','
            << r.penetration_mm << ',' << r.area_mm2 << ',' << r.law_force_n << '\n';
      }
    }
    if (!csv.flush()) throw norm2tex::Error("cannot write '" + csv_path + "'");
  }
  norm2tex::writeImage(output, plot(scenes, law, sensor));
  std::printf("wrote %s\n", output.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const norm2tex::cli::Program program = makeProgram();
  return program.main(argc, argv, [&](int argc, char** argv) { return run(program, argc, argv); });
}
