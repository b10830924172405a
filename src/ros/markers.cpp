#include "markers.hpp"

namespace norm2tex {
namespace ros_conversions {
namespace {

constexpr double kArrowMetresPerNewton = 0.005;
const char* const kGelFrames[2] = {"digit_left_gel", "digit_right_gel"};
const char* const kFingerFrames[2] = {"finger_left", "finger_right"};

visualization_msgs::Marker base(const std::string& frame, int id, int type,
                                const ros::Time& stamp) {
  visualization_msgs::Marker m;
  m.header.frame_id = frame;
  m.header.stamp = stamp;
  m.ns = "norm2tex";
  m.id = id;
  m.type = type;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.scale.x = m.scale.y = m.scale.z = 1.0;
  m.color.a = 1.0;
  return m;
}

void rgb(visualization_msgs::Marker& m, double r, double g, double b, double a = 1.0) {
  m.color.r = static_cast<float>(r);
  m.color.g = static_cast<float>(g);
  m.color.b = static_cast<float>(b);
  m.color.a = static_cast<float>(a);
}

}  // namespace

visualization_msgs::Marker objectMarker(const TexturedMesh& mesh, const ros::Time& stamp) {
  visualization_msgs::Marker m =
      base("object", 0, visualization_msgs::Marker::TRIANGLE_LIST, stamp);
  rgb(m, 0.80, 0.62, 0.42);  // wood-ish
  m.frame_locked = true;     // latched once: rviz must move it with the object frame
  m.points.reserve(mesh.triangles().size() * 3);
  for (const Eigen::Vector3i& t : mesh.triangles()) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3f& v = mesh.vertices()[t[k]];
      geometry_msgs::Point p;
      p.x = v.x();
      p.y = v.y();
      p.z = v.z();
      m.points.push_back(p);
    }
  }
  return m;
}

visualization_msgs::MarkerArray gripperMarkers(const GripperSim& sim, const ros::Time& stamp) {
  const GripperSimConfig& c = sim.config();
  visualization_msgs::MarkerArray array;
  for (int i = 0; i < 2; ++i) {
    // Gel pad: translucent, behind the gel surface (gel -z).
    visualization_msgs::Marker gel =
        base(kGelFrames[i], 10 + i, visualization_msgs::Marker::CUBE, stamp);
    gel.scale.x = c.gel_width_m;
    gel.scale.y = c.gel_height_m;
    gel.scale.z = c.gel_thickness_m;
    gel.pose.position.z = -c.gel_thickness_m / 2;
    rgb(gel, 0.75, 0.75, 0.80, 0.6);
    array.markers.push_back(gel);
    // Finger body behind the gel, 20 mm deep along the grip axis, reaching above the gel.
    visualization_msgs::Marker finger =
        base(kFingerFrames[i], 20 + i, visualization_msgs::Marker::CUBE, stamp);
    finger.scale.x = c.gel_width_m + 0.006;
    finger.scale.y = 0.020;
    finger.scale.z = c.gel_height_m + 0.030;
    finger.pose.position.y = (i == 0 ? 1.0 : -1.0) * (c.gel_thickness_m + 0.010);
    finger.pose.position.z = 0.015;
    rgb(finger, 0.25, 0.25, 0.28);
    array.markers.push_back(finger);
    // Force arrow: from the gel surface into the gel (-z), length by force.
    const GelContactState& contact = sim.contact(static_cast<Finger>(i));
    visualization_msgs::Marker arrow =
        base(kGelFrames[i], 30 + i, visualization_msgs::Marker::ARROW, stamp);
    arrow.action =
        contact.in_contact ? visualization_msgs::Marker::ADD : visualization_msgs::Marker::DELETE;
    geometry_msgs::Point tail, head;
    tail.z = kArrowMetresPerNewton * contact.normal_force_n;
    head.x = kArrowMetresPerNewton * contact.shear_force_n.x();
    head.y = kArrowMetresPerNewton * contact.shear_force_n.y();
    arrow.points = {tail, head};
    arrow.scale.x = 0.0015;  // shaft diameter
    arrow.scale.y = 0.003;   // head diameter
    arrow.scale.z = 0.004;   // head length
    rgb(arrow, 1.0, 0.2, 0.1);
    array.markers.push_back(arrow);
  }
  return array;
}

}  // namespace ros_conversions
}  // namespace norm2tex
