#include "norm2tex/calibrate/ball_press.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "norm2tex/common/error.hpp"

namespace norm2tex {

namespace {

bool ballMakesContact(double contact_radius_mm, double ball_radius_mm) {
  return contact_radius_mm < ball_radius_mm && ball_radius_mm > 0.0;  // false for NaN too
}

[[noreturn]] void throwBallTooSmall(double contact_radius_mm, double ball_radius_mm,
                                    const std::string& contact_detail) {
  std::ostringstream message;
  message << "a contact radius of " << contact_radius_mm << " mm" << contact_detail
          << " needs a ball radius above it, but the ball radius is " << ball_radius_mm
          << " mm; check the ball diameter and the mm per pixel";
  throw Error(message.str());
}

}  // namespace

double ballPressDepthMm(double contact_radius_mm, double ball_radius_mm) {
  if (!ballMakesContact(contact_radius_mm, ball_radius_mm)) {
    throwBallTooSmall(contact_radius_mm, ball_radius_mm, "");
  }
  return ball_radius_mm -
         std::sqrt(ball_radius_mm * ball_radius_mm - contact_radius_mm * contact_radius_mm);
}

cv::Mat1f ballPressIndentation(const SensorModel& model, const PressCircle& contact,
                               double ball_radius_mm) {
  const double s = model.mm_per_pixel, big_r = ball_radius_mm;
  const double a = contact.radius_px * s;
  if (!ballMakesContact(a, big_r)) {
    std::ostringstream detail;
    detail << " (" << contact.radius_px << " px at " << s << " mm/px)";
    throwBallTooSmall(a, big_r, detail.str());
  }
  const double depth = ballPressDepthMm(a, big_r);
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
