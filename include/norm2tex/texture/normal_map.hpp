#pragma once

#include <string>

#include <opencv2/core.hpp>

namespace norm2tex {

/// Green-channel convention of a tangent-space normal map. OpenGL (glTF, Blender, Substance
/// "OpenGL") stores +Y pointing up in texture space (towards v = 1, i.e. towards image row 0);
/// DirectX (Unreal, 3ds Max) stores +Y pointing down (towards increasing image rows).
enum class NormalConvention { kOpenGL, kDirectX };

/// Parses "opengl" / "directx" (case-insensitive); throws Error listing both otherwise.
NormalConvention parseNormalConvention(const std::string& text);
std::string toString(NormalConvention convention);

struct NormalMapOptions {
  NormalConvention convention = NormalConvention::kOpenGL;
  /// Texels whose decoded nz <= min_nz are masked: their slopes -nx/nz, -ny/nz are unbounded.
  double min_nz = 1e-3;
  /// Alpha (scaled to [0, 1]) at or above which a texel is valid, when the image has alpha.
  double alpha_threshold = 0.5;
};

/// Throws Error when an option is out of range (min_nz in [0, 1), alpha_threshold in [0, 1]).
void validate(const NormalMapOptions& options);

/// A decoded tangent-space normal map: unit normals and a validity mask.
///
/// Normals are stored in the *image frame*: x towards increasing columns, y towards increasing
/// rows (down), z out of the surface. Decoding is n = normalize(2c - 1) with c the RGB in
/// [0, 1]; for OpenGL maps the green component is negated to get the image-frame y. The height
/// gradients are then dx = dh/dcolumn = -nx/nz and dy = dh/drow = -ny/nz, in height units per
/// texel (for an OpenGL map this is the paper's dy = -ny/nz with ny measured along +v, negated
/// once because rows run opposite to v).
class NormalMap {
 public:
  /// Loads an 8- or 16-bit (or float) PNG/JPG/TIFF with 3 (RGB) or 4 (RGBA) channels. Alpha,
  /// when present, is the validity mask; `mask_path` (optional, any depth, single channel or
  /// colour) gives an explicit mask instead: non-zero = valid. Throws Error on missing,
  /// unreadable, empty, grayscale or mismatched-mask input.
  static NormalMap load(const std::string& path, const NormalMapOptions& options = {},
                        const std::string& mask_path = "");

  /// Decodes an image in OpenCV channel order (BGR / BGRA) of depth CV_8U, CV_16U or CV_32F
  /// (float in [0, 1]). `mask`, if not empty, must have the image's size; non-zero = valid.
  static NormalMap fromImage(const cv::Mat& image, const NormalMapOptions& options = {},
                             const cv::Mat& mask = cv::Mat());

  const cv::Mat3f& normals() const { return normals_; }
  /// 255 where the texel is usable, 0 where masked (alpha, explicit mask, nz <= min_nz, NaN).
  const cv::Mat1b& valid() const { return valid_; }
  int rows() const { return normals_.rows; }
  int cols() const { return normals_.cols; }
  int validCount() const;

 private:
  NormalMap(cv::Mat3f normals, cv::Mat1b valid);
  cv::Mat3f normals_;
  cv::Mat1b valid_;
};

/// Height gradients of image-frame unit normals: dx = -nx/nz, dy = -ny/nz where valid, 0
/// elsewhere. Texels with nz <= min_nz are treated as invalid (gradients 0).
void normalsToGradients(const cv::Mat3f& normals, const cv::Mat1b& valid, double min_nz,
                        cv::Mat1f& dx, cv::Mat1f& dy);

}  // namespace norm2tex
