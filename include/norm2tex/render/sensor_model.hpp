#pragma once

#include <array>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace norm2tex {

/// One of the DIGIT's three LEDs.
struct LedModel {
  std::string name;        ///< "red", "green", "blue"
  cv::Vec3d position_mm;   ///< in the gel frame (see SensorModel)
  cv::Vec3d color_bgr;     ///< colour, each channel in [0, 1], OpenCV order
  double intensity = 1.0;  ///< relative, >= 0
};

/// Elastomer smoothing (see GelModel): Taxim-style pyramid of Gaussian blurs that restores the
/// contact core after each level, then one small blur.
struct GelOptions {
  std::vector<double> pyramid_sigmas_mm = {1.0, 0.5, 0.25, 0.1};  ///< coarse to fine (Taxim)
  double core_fraction = 0.4;   ///< pixels indented more than this x max indentation: the core
  double final_sigma_mm = 0.1;  ///< last blur over everything
};

/// Everything about one DIGIT that the renderer needs, loaded from config/digit.yaml.
///
/// Gel frame (shared by the CLI, the tests and the ROS nodes): origin at the centre of the
/// undeformed gel surface; +x towards increasing image columns (right); +y towards increasing
/// image rows (down); +z out of the gel towards the object. The camera sits behind the gel and
/// looks along +z. Pixel (row r, column c) sees the gel point
/// x = (c + 0.5 - cols / 2) * mm_per_pixel, y = (r + 0.5 - rows / 2) * mm_per_pixel.
struct SensorModel {
  int rows = 320;                 ///< image height, pixels (portrait QVGA as drivers publish)
  int cols = 240;                 ///< image width, pixels
  double mm_per_pixel = 0.08;     ///< gel millimetres per pixel at the gel surface
  double gel_thickness_mm = 4.6;  ///< indentation is clamped to this
  double gel_curvature_radius_mm = 0.0;  ///< 0 = flat gel; else a dome of this radius
  double fx = 277.1, fy = 277.1;         ///< camera_info intrinsics, pixels
  double cx = 119.5, cy = 159.5;         ///< principal point, pixels
  std::array<LedModel, 3> leds;          ///< red, green, blue
  double shading_gain = 1.0;     ///< scales (shading - flat shading) before adding background
  double noise_sigma = 2.0;      ///< Gaussian pixel noise, grey levels of 255
  std::string background_image;  ///< user's no-contact frame (BGR); empty = synthetic
  GelOptions gel;

  double gelWidthMm() const { return cols * mm_per_pixel; }
  double gelHeightMm() const { return rows * mm_per_pixel; }
  cv::Size imageSize() const { return {cols, rows}; }
  /// Gel-frame x, y (mm) of a pixel centre.
  cv::Point2d pixelToGelMm(double row, double col) const;
};

/// Defaults for a DIGIT at QVGA (320 x 240) or VGA (640 x 480): same gel, halved mm per pixel.
SensorModel makeDigitSensorModel(bool vga = false);

/// Loads config/digit.yaml (every key optional, defaults above; `preset: qvga|vga` first).
/// A relative background_image is resolved against the yaml's directory. Throws Error naming
/// the file and key for unreadable yaml or a value out of range.
SensorModel loadSensorModel(const std::string& yaml_path);

/// Throws Error naming the first field out of range and its valid range.
void validate(const SensorModel& model);

}  // namespace norm2tex
