// The nodes as nodelets, so one manager shares messages between the physics, the renderers and
// the recorder without copies: norm2tex/ContactSimNodelet, norm2tex/TactileRendererNodelet.
#include <memory>

#include <nodelet/nodelet.h>
#include <class_loader/register_macro.hpp>

#include "contact_sim.hpp"
#include "norm2tex/common/error.hpp"
#include "tactile_renderer_ros.hpp"

namespace norm2tex {

class ContactSimNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    try {
      // Multi-threaded handles: ~step blocks its callback while the renderers work.
      sim_ = std::make_unique<ContactSim>(getMTNodeHandle(), getMTPrivateNodeHandle());
    } catch (const Error& e) {
      // A nodelet cannot exit its manager: report and stop the manager's ROS node.
      NODELET_FATAL("contact_sim: %s", e.what());
      ros::shutdown();
    }
  }
  std::unique_ptr<ContactSim> sim_;
};

class TactileRendererNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    try {
      // Single-threaded handles: frames are rendered one after another, in order.
      renderer_ = std::make_unique<TactileRendererRos>(getNodeHandle(), getPrivateNodeHandle());
    } catch (const Error& e) {
      NODELET_FATAL("tactile_renderer: %s", e.what());
      ros::shutdown();
    }
  }
  std::unique_ptr<TactileRendererRos> renderer_;
};

}  // namespace norm2tex

// Debian ships ROS 1 nodelet on class_loader; pluginlib's export macro expands to this.
CLASS_LOADER_REGISTER_CLASS(norm2tex::ContactSimNodelet, nodelet::Nodelet)
CLASS_LOADER_REGISTER_CLASS(norm2tex::TactileRendererNodelet, nodelet::Nodelet)
