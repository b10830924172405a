#include "norm2tex/sim/contact_resultant.hpp"

namespace norm2tex {

ContactResultant contactResultant(const std::vector<PointLoad>& points) {
  ContactResultant out;
  if (points.empty()) return out;
  Eigen::Vector2d weighted = Eigen::Vector2d::Zero(), plain = Eigen::Vector2d::Zero();
  for (const PointLoad& p : points) {
    out.normal_n += p.normal_n;
    out.tangential_n += p.tangential_n;
    weighted += p.normal_n * p.position_m;
    plain += p.position_m;
  }
  // Points the solver left unloaded still say where the contact is; they carry no moment anyway.
  out.pressure_centre_m =
      out.normal_n > 0.0 ? Eigen::Vector2d(weighted / out.normal_n)
                         : Eigen::Vector2d(plain / static_cast<double>(points.size()));
  for (const PointLoad& p : points) {
    const Eigen::Vector2d arm = p.position_m - out.pressure_centre_m;
    out.twist_moment_nm += arm.x() * p.tangential_n.y() - arm.y() * p.tangential_n.x();
  }
  return out;
}

}  // namespace norm2tex
