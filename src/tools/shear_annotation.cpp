#include "shear_annotation.hpp"

#include <cmath>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "cli_arguments.hpp"

namespace norm2tex {
namespace cli {
namespace {

// A cell mask of the grid, drawn at image size (nearest cell), its outline in `colour`.
void outline(cv::Mat3b& image, const cv::Mat1b& cells, int cell_px, const cv::Scalar& colour) {
  if (cells.empty() || cv::countNonZero(cells) == 0) return;
  cv::Mat1b big;
  cv::resize(cells, big, cv::Size(cells.cols * cell_px, cells.rows * cell_px), 0, 0,
             cv::INTER_NEAREST);
  big = big(cv::Rect(0, 0, image.cols, image.rows)).clone();
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(big, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  cv::drawContours(image, contours, -1, colour, 1, cv::LINE_AA);
}

}  // namespace

void drawShearAnnotations(cv::Mat3b& image, const ShearFrame& shear, double gain) {
  cv::Mat1b contact;
  cv::compare(shear.traction.pressure_mpa, 0.0f, contact, cv::CMP_GT);
  outline(image, contact, shear.cell_px, cv::Scalar(255, 255, 255));
  outline(image, shear.traction.stick, shear.cell_px, cv::Scalar(0, 255, 0));
  for (const Marker& m : shear.markers) {
    const cv::Point2f tip = m.rest_px + gain * (m.current_px - m.rest_px);
    if (cv::norm(tip - m.rest_px) < 1.0) continue;
    cv::arrowedLine(image, m.rest_px, tip, cv::Scalar(0, 255, 255), 1, cv::LINE_AA, 0, 0.3);
  }
}

ShearLoad parseShearLoad(const std::string& text, const std::string& option) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      size_t used = 0;
      values.push_back(std::stod(item, &used));
      if (item.find_first_not_of(" \t", used) != std::string::npos) throw std::invalid_argument("");
    } catch (const std::exception&) {
      throw UsageError(option + ": not a number: '" + item + "' in '" + text + "'");
    }
  }
  if (values.size() != 2 && values.size() != 3) {
    throw UsageError(option + " needs \"FX,FY\" or \"FX,FY,T\" (N, N, N m), got '" + text + "'");
  }
  ShearLoad load;
  load.force_n = {values[0], values[1]};
  if (values.size() == 3) load.torque_nm = values[2];
  if (!load.force_n.allFinite() || !std::isfinite(load.torque_nm)) {
    throw UsageError(option + ": '" + text + "' is not finite");
  }
  return load;
}

std::vector<std::string> splitLoads(const std::string& text) {
  std::vector<std::string> parts;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ';')) {
    if (!item.empty()) parts.push_back(item);
  }
  return parts;
}

}  // namespace cli
}  // namespace norm2tex
