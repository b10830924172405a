#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <ros/callback_queue.h>
#include <ros/ros.h>

#include "lock_step.hpp"
#include "norm2tex/EpisodeInfo.h"
#include "norm2tex/Step.h"
#include "norm2tex/mesh/object_mesh.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/sim/contact_patch.hpp"
#include "norm2tex/gel/gel_law.hpp"
#include "norm2tex/sim/probe_scenario.hpp"
#include "norm2tex/sim/probe_schedule.hpp"

namespace norm2tex {

/// Validated private parameters of probe_sim (docs/ros.md, "probe_sim").
struct ProbeSimParams {
  std::string sensor_name = "digit_left";  ///< ~sensor_name: the probing DIGIT
  std::string sensor;                      ///< ~sensor: sensor yaml
  std::string scene;                       ///< ~scene: the object (mesh, scale) and gel law
  std::string mesh;                        ///< ~mesh: replaces the scene's object when set
  double scale = 1.0;                      ///< ~scale of ~mesh
  /// ~material: a name, a comma-separated list, or "all" (every shipped material), in order.
  std::vector<std::string> materials;
  int variants = -1;                 ///< ~variants per material; < 0: the material's variant_count
  int samples = 100;                 ///< ~samples: images per material
  std::int64_t seed = 0;             ///< ~seed of the dataset
  int shard = 0, num_shards = 1;     ///< ~shard of ~num_shards
  ProbeConfig probe;                 ///< ~press_depth_min/max, ~slides, ~slide_step (metres)
  double beta = -1.0;                ///< ~beta [mm] label; < 0: each material's beta_mm
  double frame_rate = 60.0;          ///< ~frame_rate [Hz] of simulated time
  std::vector<std::string> renderers;  ///< ~renderers: answers each frame waits for
  double render_timeout = 10.0;        ///< ~render_timeout [s of wall time]
  /// ~ready_timeout [s of wall time] for the renderers to start (texture bakes included)
  double ready_timeout = 60.0;
  bool autostart = true;  ///< ~autostart: run the whole schedule at once; false: ~step drives it
  /// ~window: frames in flight at once (1 = strict lock-step); every frame is still answered.
  int window = 4;
};

/// Reads and validates the private parameters; throws Error naming the parameter at fault.
ProbeSimParams readProbeSimParams(const ros::NodeHandle& private_nh);

/// The paper's data collection as a synchronous frame source: one DIGIT, free of any gripper,
/// presses onto random surface points of the object and slides a little (ProbeScenario), through
/// every material variant of the plan (ProbeSchedule). Per frame it publishes /clock, TF (world
/// -> object, world -> <sensor>_gel), <sensor>/contact and ~frame (with the texture to render);
/// per press an EpisodeInfo on /episode. Every frame waits for ~renderers (LockStep), so a
/// recorder listed there writes every frame before the next one. The last frame says so.
class ProbeSim {
 public:
  /// Throws Error (bad parameter, unreadable scene/mesh/material, no /use_sim_time).
  ProbeSim(ros::NodeHandle nh, ros::NodeHandle private_nh);
  ~ProbeSim();

  /// Frames of this shard's plan, and how many are published so far.
  std::uint64_t plannedFrames() const { return schedule_->frames(); }

 private:
  /// Publishes the next frame of the plan; false when the plan is done.
  bool advanceFrame();
  void run();
  bool onStep(Step::Request& request, Step::Response& response);
  ros::Time stamp() const;

  ProbeSimParams params_;
  ObjectMesh object_;
  std::string object_name_;  ///< label: the scene's object name or the mesh file's stem
  SensorModel sensor_;
  GelLaw gel_law_ = GelLaw::taximDefault();
  std::unique_ptr<ProbeSchedule> schedule_;
  std::vector<double> block_beta_;  ///< beta label of each block, mm
  std::unique_ptr<ProbeScenario> scenario_;
  int scenario_block_ = -1;
  /// The block whose texture comes after scenario_block_'s (-1: none): named in every SimFrame
  /// so that renderers prepare it in the background.
  int next_texture_block_ = -1;
  std::unique_ptr<ContactPatchMeter> meter_;
  std::size_t next_press_ = 0;
  std::vector<ProbeFrame> press_frames_;  ///< frames of the current press
  std::size_t next_in_press_ = 0;
  std::int64_t frame_ = 0, period_ns_ = 0;
  std::uint32_t episode_ = 0;
  std::uint64_t missing_images_ = 0;  ///< frames a renderer reported without an image
  ros::WallTime started_;

  std::mutex mutex_;
  std::atomic<bool> stop_{false};
  /// ~step's queue: declared before the server on it, which removes itself from it when
  /// destroyed.
  ros::CallbackQueue service_queue_;
  ros::NodeHandle nh_, private_nh_;
  ros::Publisher tf_pub_, clock_pub_, episode_pub_, frame_pub_, contact_pub_, marker_pub_;
  ros::ServiceServer step_srv_;
  std::unique_ptr<LockStep> lock_step_;
  std::unique_ptr<ros::AsyncSpinner> service_spinner_;
  std::thread runner_;
};

}  // namespace norm2tex
