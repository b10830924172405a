// The nodes as nodelets, so one manager shares messages between the physics, the renderers and
// the recorder without copies: norm2tex/ContactSimNodelet, norm2tex/HandSimNodelet, norm2tex/ProbeSimNodelet,
// norm2tex/TactileRendererNodelet, norm2tex/DatasetRecorderNodelet.
#include <memory>

#include <nodelet/nodelet.h>
#include <class_loader/register_macro.hpp>

#include "contact_sim.hpp"
#include "hand_sim_ros.hpp"
#include "dataset_recorder.hpp"
#include "launch_end.hpp"
#include "params.hpp"
#include "probe_sim.hpp"
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

class HandSimNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    try {
      sim_ = std::make_unique<HandSimRos>(getMTNodeHandle(), getMTPrivateNodeHandle());
    } catch (const Error& e) {
      NODELET_FATAL("hand_sim: %s", e.what());
      ros::shutdown();
    }
  }
  std::unique_ptr<HandSimRos> sim_;
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

class ProbeSimNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    try {
      sim_ = std::make_unique<ProbeSim>(getMTNodeHandle(), getMTPrivateNodeHandle());
    } catch (const Error& e) {
      NODELET_FATAL("probe_sim: %s", e.what());
      ros::shutdown();
    }
  }
  std::unique_ptr<ProbeSim> sim_;
};

/// The recorder in the manager: no copies of the images it writes. When it is done (sample
/// target, the source's last frame, a write error) it closes the bag and, with
/// ~shutdown_when_done (default true), ends the launch (endParentLaunch) or shuts the manager
/// down as the node would exit.
class DatasetRecorderNodelet : public nodelet::Nodelet {
 public:
  ~DatasetRecorderNodelet() override {
    if (recorder_) recorder_->close();
  }

 private:
  void onInit() override {
    try {
      recorder_ = std::make_unique<DatasetRecorder>(getNodeHandle(), getPrivateNodeHandle());
    } catch (const Error& e) {
      NODELET_FATAL("dataset_recorder: %s", e.what());
      ros::shutdown();
      return;
    }
    ros_params::readParam(getPrivateNodeHandle(), "shutdown_when_done", shutdown_when_done_, true);
    // On the recorder's own (single-threaded) queue: never concurrent with its callbacks.
    done_timer_ = getNodeHandle().createWallTimer(ros::WallDuration(0.01), [this](const auto&) {
      if (!recorder_->done()) return;
      done_timer_.stop();
      recorder_->close();
      if (!recorder_->error().empty()) NODELET_ERROR("dataset_recorder: %s", recorder_->error().c_str());
      if (!shutdown_when_done_) return;
      // Done as planned under roslaunch: end the whole launch as Ctrl-C would (roslaunch then
      // stops this manager), without the red banner a required node's exit prints. A failure
      // keeps that banner: it is one. Should roslaunch not stop us, shut down after all.
      if (recorder_->error().empty() && endParentLaunch()) {
        fallback_timer_ = getNodeHandle().createWallTimer(
            ros::WallDuration(10.0), [](const auto&) { ros::requestShutdown(); }, true);
        return;
      }
      ros::requestShutdown();
    });
  }
  std::unique_ptr<DatasetRecorder> recorder_;
  ros::WallTimer done_timer_, fallback_timer_;
  bool shutdown_when_done_ = true;
};

}  // namespace norm2tex

// Debian ships ROS 1 nodelet on class_loader; pluginlib's export macro expands to this.
CLASS_LOADER_REGISTER_CLASS(norm2tex::ContactSimNodelet, nodelet::Nodelet)
CLASS_LOADER_REGISTER_CLASS(norm2tex::HandSimNodelet, nodelet::Nodelet)
CLASS_LOADER_REGISTER_CLASS(norm2tex::TactileRendererNodelet, nodelet::Nodelet)
CLASS_LOADER_REGISTER_CLASS(norm2tex::ProbeSimNodelet, nodelet::Nodelet)
CLASS_LOADER_REGISTER_CLASS(norm2tex::DatasetRecorderNodelet, nodelet::Nodelet)
