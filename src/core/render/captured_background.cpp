// The user's own no-contact frame, read and fitted to the sensor's image size. (The synthetic
// frame is synthetic_background.cpp's.)

#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "norm2tex/render/digit_shader.hpp"
#include "norm2tex/common/error.hpp"
#include "norm2tex/common/image_io.hpp"

namespace norm2tex {

cv::Mat3b loadBackground(const std::string& path, cv::Size size) {
  if (size.width <= 0 || size.height <= 0) {
    throw Error("background image '" + path + "': requested size " + std::to_string(size.width) +
                " x " + std::to_string(size.height) + " is not valid");
  }
  // UNCHANGED keeps 16-bit depth and alpha so both can be handled explicitly below.
  cv::Mat image = readImage(path, cv::IMREAD_UNCHANGED, "background image");
  if (image.depth() == CV_16U) {
    image.convertTo(image, CV_8U, 255.0 / 65535.0);
  } else if (image.depth() != CV_8U) {
    throw Error("background image '" + path +
                "' has an unsupported pixel depth (only 8- and 16-bit integer images are "
                "accepted)");
  }
  switch (image.channels()) {
    case 1:
      cv::cvtColor(image, image, cv::COLOR_GRAY2BGR);
      break;
    case 3:
      break;
    case 4:
      cv::cvtColor(image, image, cv::COLOR_BGRA2BGR);  // alpha means nothing for a frame
      break;
    default:
      throw Error("background image '" + path + "' has " + std::to_string(image.channels()) +
                  " channels; valid: 1 (gray), 3 (BGR) or 4 (BGRA)");
  }
  // Resizing between presets is fine (a VGA frame for a QVGA model), but a landscape frame for
  // a portrait sensor is a frame the driver did not transpose: stretching it would put the LED
  // glows in the wrong places without anyone noticing.
  const bool image_portrait = image.rows > image.cols, model_portrait = size.height > size.width;
  if (image.rows != image.cols && size.height != size.width && image_portrait != model_portrait) {
    throw Error("background image '" + path + "' is " + std::to_string(image.cols) + " x " +
                std::to_string(image.rows) + " (" + (image_portrait ? "portrait" : "landscape") +
                ") but the sensor image is " + std::to_string(size.width) + " x " +
                std::to_string(size.height) + " (" + (model_portrait ? "portrait" : "landscape") +
                "); rotate it the way your driver publishes frames");
  }
  if (image.size() != size) cv::resize(image, image, size, 0.0, 0.0, cv::INTER_AREA);
  return image;
}

}  // namespace norm2tex
