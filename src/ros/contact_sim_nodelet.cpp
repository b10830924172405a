// contact_sim as a nodelet (norm2tex/ContactSimNodelet): shares a manager with the renderers
// and the recorder so messages pass without copies.
#include <memory>

#include <nodelet/nodelet.h>
#include <class_loader/register_macro.hpp>

#include "contact_sim.hpp"
#include "norm2tex/common/error.hpp"

namespace norm2tex {

class ContactSimNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    try {
      sim_ = std::make_unique<ContactSim>(getMTNodeHandle(), getMTPrivateNodeHandle());
    } catch (const Error& e) {
      // A nodelet cannot exit its manager: report and stop the manager's ROS node.
      NODELET_FATAL("contact_sim: %s", e.what());
      ros::shutdown();
    }
  }
  std::unique_ptr<ContactSim> sim_;
};

}  // namespace norm2tex

// Debian ships ROS 1 nodelet on class_loader; pluginlib's export macro expands to this.
CLASS_LOADER_REGISTER_CLASS(norm2tex::ContactSimNodelet, nodelet::Nodelet)
