#include "norm2tex/materials/procedural_material.hpp"

#include <cmath>
#include <sstream>

#include "materials/materials.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/common/huge_pages.hpp"

namespace norm2tex {
namespace {

std::string joined(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& n : names) text += (text.empty() ? "" : ", ") + n;
  return text;
}

}  // namespace

ProceduralMaterial::ProceduralMaterial(std::vector<MaterialParameter> parameters)
    : parameters_(std::move(parameters)) {}

std::size_t ProceduralMaterial::indexOf(const std::string& name) const {
  for (std::size_t i = 0; i < parameters_.size(); ++i) {
    if (parameters_[i].name == name) return i;
  }
  std::vector<std::string> names;
  for (const MaterialParameter& p : parameters_) names.push_back(p.name);
  throw Error(this->name() + " has no parameter '" + name + "'; valid: " + joined(names));
}

double ProceduralMaterial::parameter(const std::string& name) const {
  return parameters_[indexOf(name)].value;
}

void ProceduralMaterial::setParameter(const std::string& name, double value) {
  MaterialParameter& p = parameters_[indexOf(name)];
  if (!(value >= p.min && value <= p.max)) {  // also rejects NaN
    std::ostringstream message;
    message << this->name() << "." << name << " = " << value << " is out of range; valid: ["
            << p.min << ", " << p.max << "]" << (p.unit.empty() ? "" : " " + p.unit)
            << (p.integer ? " (integer)" : "");
    throw Error(message.str());
  }
  p.value = p.integer ? std::round(value) : value;
  update();
}

void ProceduralMaterial::setSeed(std::uint64_t seed) {
  seed_ = seed;
  update();
}

void ProceduralMaterial::checkGrid(cv::Size size, double mm_per_texel) {
  if (size.width <= 0 || size.height <= 0) {
    throw Error("material render: size " + std::to_string(size.width) + " x " +
                std::to_string(size.height) + " must be positive");
  }
  if (!(mm_per_texel > 0.0) || !std::isfinite(mm_per_texel)) {
    throw Error("material render: mm_per_texel = " + std::to_string(mm_per_texel) +
                " is out of range; valid: > 0 mm");
  }
}

namespace {

/// Fills an image with `at(row, column)` (the material's texel-centre convention lives in the
/// callers, through texelX / texelY).
template <typename Pixel, typename Function>
cv::Mat_<Pixel> renderGrid(cv::Size size, Function at) {
  cv::Mat_<Pixel> image;
  createWithHugePages(image, size.height, size.width);  // a 2048^2 texture's 16 MB
  for (int r = 0; r < size.height; ++r) {
    Pixel* row = image.template ptr<Pixel>(r);
    for (int c = 0; c < size.width; ++c) row[c] = at(r, c);
  }
  return image;
}

}  // namespace

cv::Mat1f ProceduralMaterial::renderHeightMm(cv::Size size, double mm_per_texel,
                                             cv::Point2d origin_mm) const {
  checkGrid(size, mm_per_texel);
  return renderGrid<float>(size, [&](int r, int c) {
    return static_cast<float>(
        heightMm(texelX(c, mm_per_texel, origin_mm), texelY(r, mm_per_texel, origin_mm)));
  });
}

cv::Mat3b ProceduralMaterial::renderAlbedo(cv::Size size, double mm_per_texel,
                                           cv::Point2d origin_mm) const {
  checkGrid(size, mm_per_texel);
  return renderGrid<cv::Vec3b>(size, [&](int r, int c) {
    return albedo(texelX(c, mm_per_texel, origin_mm), texelY(r, mm_per_texel, origin_mm));
  });
}

std::vector<std::string> materialNames() { return {"wood", "fabric", "rock", "smooth", "print3d"}; }

std::unique_ptr<ProceduralMaterial> makeMaterial(const std::string& name) {
  if (name == "wood") return materials::makeWood();
  if (name == "fabric") return materials::makeFabric();
  if (name == "rock") return materials::makeRock();
  if (name == "smooth") return materials::makeSmooth();
  if (name == "print3d") return materials::makePrint3d();
  throw Error("material '" + name + "' is not known; valid: " + joined(materialNames()));
}

}  // namespace norm2tex
