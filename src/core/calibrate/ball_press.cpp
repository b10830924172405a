#include "norm2tex/calibrate/ball_press.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "norm2tex/common/error.hpp"

namespace norm2tex {

cv::Mat1f ballPressIndentation(const SensorModel& model, const PressCircle& contact,
                               double ball_radius_mm) {
  const double s = model.mm_per_pixel, big_r = ball_radius_mm;
  const double a = contact.radius_px * s;
  if (!(a < big_r) || !(big_r > 0.0)) {
    std::ostringstream message;
    message << "a contact radius of " << a << " mm (" << contact.radius_px << " px at " << s
            << " mm/px) needs a ball radius above it, but the ball radius is " << big_r
            << " mm; check the ball diameter and the mm per pixel";
    throw Error(message.str());
  }
  const double depth = big_r - std::sqrt(big_r * big_r - a * a);
  cv::Mat1f h(model.rows, model.cols, 0.0f);
  const int r0 = std::max(0, static_cast<int>(std::floor(contact.centre_px.y - contact.radius_px)));
  const int r1 = std::min(model.rows - 1,
                          static_cast<int>(std::ceil(contact.centre_px.y + contact.radius_px)));
  const int c0 = std::max(0, static_cast<int>(std::floor(contact.centre_px.x - contact.radius_px)));
  const int c1 = std::min(model.cols - 1,
                          static_cast<int>(std::ceil(contact.centre_px.x + contact.radius_px)));
  for (int r = r0; r <= r1; ++r) {
    float* row = h.ptr<float>(r);
    for (int c = c0; c <= c1; ++c) {
      const double dx = (c - contact.centre_px.x) * s, dy = (r - contact.centre_px.y) * s;
      const double rho2 = dx * dx + dy * dy;
      if (rho2 >= a * a) continue;
      const double value = depth - (big_r - std::sqrt(big_r * big_r - rho2));
      if (value > 0.0) row[c] = static_cast<float>(value);
    }
  }
  return h;
}

}  // namespace norm2tex
