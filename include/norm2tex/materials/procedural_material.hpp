#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "norm2tex/common/huge_pages.hpp"

namespace norm2tex {

/// One tunable number of a procedural material, with its valid range and unit.
struct MaterialParameter {
  std::string name;             ///< e.g. "ring_spacing_mm"
  double value = 0.0;           ///< current value
  double min = 0.0, max = 0.0;  ///< valid range, inclusive
  std::string unit;             ///< "mm", "deg", "1/mm^2" or "" (dimensionless)
  std::string description;      ///< one line
  /// The value is an integer choice (e.g. fabric "weave", rock "octaves"): setParameter rounds
  /// to the nearest integer, so parameter() returns what the material uses.
  bool integer = false;
};

/// A procedural surface texture in physical units: a relief height and an albedo colour at any
/// point (x_mm, y_mm) of the texture plane. x runs right and y down, as image columns and rows;
/// angles ("deg" parameters) are measured from +x towards +y, i.e. clockwise on screen.
///
/// Everything is a pure function of (parameters, seed): the same values and seed give the same
/// heights bit for bit on every call (noise is integer hashing and IEEE arithmetic; only a few
/// set-up values use libm's sin / cos); there is no hidden RNG state, and const calls are safe
/// from several threads. Heights are continuous in (x, y), so their gradients encode into a
/// normal map.
class ProceduralMaterial {
 public:
  virtual ~ProceduralMaterial() = default;

  virtual std::string name() const = 0;  ///< "wood", "fabric", ...

  const std::vector<MaterialParameter>& parameters() const { return parameters_; }
  /// Throws Error listing the valid names if the material has no such parameter.
  double parameter(const std::string& name) const;
  /// Throws Error listing the valid names for an unknown name, or stating the range and unit
  /// for a value out of range (or not finite). Integer parameters are rounded.
  void setParameter(const std::string& name, double value);
  void setSeed(std::uint64_t seed);
  std::uint64_t seed() const { return seed_; }

  /// Relief height in mm at (x_mm, y_mm) of the texture plane (x right, y down as image
  /// columns / rows). Continuous, deterministic for (parameters, seed), no state.
  virtual double heightMm(double x_mm, double y_mm) const = 0;
  /// Albedo preview colour (OpenCV BGR).
  virtual cv::Vec3b albedo(double x_mm, double y_mm) const = 0;

  /// Grid evaluation: texel (r, c) is at (origin.x + (c + 0.5) * mm_per_texel,
  /// origin.y + (r + 0.5) * mm_per_texel). The base versions loop over heightMm / albedo;
  /// materials override them where a faster path exists, with results identical to the
  /// per-point functions. Throws Error for an empty size or mm_per_texel <= 0.
  virtual cv::Mat1f renderHeightMm(cv::Size size, double mm_per_texel,
                                   cv::Point2d origin_mm = {}) const;
  virtual cv::Mat3b renderAlbedo(cv::Size size, double mm_per_texel,
                                 cv::Point2d origin_mm = {}) const;

 protected:
  explicit ProceduralMaterial(std::vector<MaterialParameter> parameters);
  ProceduralMaterial(const ProceduralMaterial&) = default;
  ProceduralMaterial& operator=(const ProceduralMaterial&) = default;

  /// Recomputes whatever a material caches from its parameters and seed. Called after every
  /// setParameter / setSeed; derived constructors call it once themselves (a base constructor
  /// cannot call a virtual function).
  virtual void update() {}

  /// Value of the parameter at `index` (the order of the constructor's list): the fast path
  /// for update(), which caches what heightMm needs.
  double value(std::size_t index) const { return parameters_[index].value; }

  /// The x / y coordinate of texel column c / row r, exactly as the grid functions define it.
  static double texelX(int c, double mm_per_texel, cv::Point2d origin) {
    return origin.x + (c + 0.5) * mm_per_texel;
  }
  static double texelY(int r, double mm_per_texel, cv::Point2d origin) {
    return origin.y + (r + 0.5) * mm_per_texel;
  }
  /// Throws Error unless size is non-empty and mm_per_texel is positive and finite.
  static void checkGrid(cv::Size size, double mm_per_texel);

  /// The base renderHeightMm's loop around `height(x_mm, y_mm)` (a double): for overrides
  /// that evaluate without a virtual call and a thread-local look-up per texel. Same values.
  template <typename Height>
  static cv::Mat1f renderHeightGrid(cv::Size size, double mm_per_texel, cv::Point2d origin_mm,
                                    Height height) {
    checkGrid(size, mm_per_texel);
    cv::Mat1f image;
    createWithHugePages(image, size.height, size.width);  // a 2048^2 texture's 16 MB
    for (int r = 0; r < size.height; ++r) {
      float* row = image.ptr<float>(r);
      const double y = texelY(r, mm_per_texel, origin_mm);
      for (int c = 0; c < size.width; ++c) {
        row[c] = static_cast<float>(height(texelX(c, mm_per_texel, origin_mm), y));
      }
    }
    return image;
  }

 private:
  std::size_t indexOf(const std::string& name) const;

  std::vector<MaterialParameter> parameters_;
  std::uint64_t seed_ = 0;
};

/// Exactly {"wood", "fabric", "rock", "smooth", "print3d"}.
std::vector<std::string> materialNames();

/// A material with its default parameters and seed 0. Throws Error listing the valid names.
std::unique_ptr<ProceduralMaterial> makeMaterial(const std::string& name);

}  // namespace norm2tex
