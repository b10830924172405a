#pragma once

#include <cstdint>
#include <list>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include <image_transport/image_transport.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "norm2tex/FrameRendered.h"
#include "norm2tex/SimFrame.h"
#include "norm2tex/render/object_texture.hpp"
#include "norm2tex/render/object_texture_cache.hpp"
#include "norm2tex/render/tactile_renderer.hpp"
#include "frame_trace.hpp"
#include "transform_waiter.hpp"

namespace norm2tex {

/// Validated private parameters of tactile_renderer (see README, "tactile_renderer").
struct TactileRendererParams {
  std::string sensor_name = "digit_left";  ///< ~sensor_name: topic namespace of the sensor
  std::string sensor;                      ///< ~sensor: sensor yaml
  std::string gel_frame;                   ///< ~gel_frame (default <sensor_name>_gel)
  std::string object_frame = "object";     ///< ~object_frame
  std::string scene;            ///< ~scene: the object mesh and scale come from this scene yaml ...
  std::string mesh;             ///< ~mesh: ... unless given here (file or box:/sphere: primitive)
  double scale = 1.0;           ///< ~scale with ~mesh
  std::string material;         ///< ~material: procedural material name, or "" (~material none)
  std::string material_config;  ///< resolved config/materials/<material>.yaml
  int variant = 0;              ///< ~variant
  int material_seed = 0;        ///< ~material_seed
  std::string normal_map;       ///< ~normal_map: a normal map file instead of a material
  std::string convention = "opengl";  ///< ~convention of the normal map: opengl | directx
  std::string atlas;                  ///< ~atlas: a baked H_global float TIFF instead
  double beta = -1.0;                 ///< ~beta [mm]; < 0: the material's beta_mm (0.1 for files)
  std::string background;     ///< ~background: the user's no-contact DIGIT frame ("" = synthetic)
  int noise_seed = 0;         ///< ~noise_seed; < 0: no noise
  bool publish_mask = false;  ///< ~publish_mask: also /<sensor>/contact_mask (mono8)
  double tf_timeout = 1.0;    ///< ~tf_timeout [s of wall time] for the pose at a frame's stamp
  /// ~opencv_threads: OpenCV's thread pool size once the first texture is ready (process-wide,
  /// so shared by the nodelets of a manager); 1 renders on the frame callback's thread alone,
  /// -1 leaves OpenCV's default.
  int opencv_threads = 1;
  /// ~queue_size: outgoing messages kept per subscriber of each topic. A subscriber further
  /// behind than this loses the oldest (ROS's publisher queue): 100 frames is 1.7 s at 60 Hz, or
  /// a ~step of many frames outrunning a subscriber by 100 images (23 MB of images per topic).
  int queue_size = 100;
  std::string frame_topic = "contact_sim/frame";      ///< ~frame_topic: SimFrame source
  std::string answer_topic = "contact_sim/rendered";  ///< ~answer_topic: FrameRendered sink
  /// ~texture_from_frame: render each frame with the material and variant its SimFrame names
  /// (probe datasets step through every variant); ~material and ~variant give the first one.
  bool texture_from_frame = false;
  /// ~trace_file: write when each frame's stages were reached to this CSV at shutdown
  /// (scripts/ros_benchmark --trace); "" = none.
  std::string trace_file;
  /// ~cpu: the thread that renders the frames runs on this CPU only (real time: one CPU per
  /// sensor keeps the two renders in parallel); -1: wherever the scheduler puts it.
  int cpu = -1;
  /// ~rehearse_ms: real time only. This long before the next frame is due, render the last
  /// frame again and discard it, so that the next render finds its memory in the caches: a
  /// thread that slept through a 60 Hz period can find them emptied (on the project's VM a
  /// paced render took 1.8-2.0 ms alone, 1.5-1.6 ms rehearsed 5 ms before). Costs one render
  /// per frame. 0: off.
  double rehearse_ms = 0.0;
};

TactileRendererParams readTactileRendererParams(const ros::NodeHandle& private_nh);

/// The tactile_renderer's work, shared by node and nodelet: for every SimFrame it looks up the
/// object pose in the gel frame at exactly the frame's stamp, renders H_sensor + beta H_local
/// through TactileRenderer (with the frame's tangential load, when the sensor has markers or
/// someone listens to shear), and publishes image_raw (bgr8), camera_info, depth (32FC1, m),
/// optionally contact_mask, markers (when the sensor model has them) and shear (32FC2, m, to
/// listeners), all with the frame's stamp and the gel frame, then answers with a
/// FrameRendered. A pose that does not arrive within ~tf_timeout is counted and warned about;
/// no image is faked for it.
class TactileRendererRos {
 public:
  /// Throws Error (bad parameter, unreadable sensor/scene/mesh/texture/background).
  TactileRendererRos(ros::NodeHandle nh, ros::NodeHandle private_nh);
  ~TactileRendererRos();

 private:
  void onFrame(const SimFrame::ConstPtr& frame);
  /// ~cpu: pins the frame thread (once, from its first frame).
  void placeFrameThread();
  /// A frame offered again: answers it as before (or ignores one too old) and returns true.
  bool answerAgain(const SimFrame& frame);
  /// The object in the gel frame at exactly `stamp` (TF, waited for); throws Error naming why not.
  Eigen::Isometry3d objectInGelAt(const ros::Time& stamp);
  /// The gel's normal force the source gives for this sensor, if it gives one.
  std::optional<double> normalForceIn(const SimFrame& frame) const;
  /// Renders the frame and publishes its image (and camera_info, depth, mask to listeners).
  void renderAndPublish(const SimFrame& frame);
  /// Publishes a synchronous frame's answer and keeps it for a frame offered again.
  void keepAnswer(const FrameRendered& answer);
  bool anyoneListens() const;
  /// Loads (or takes from the cache) a texture and gives it to the renderer.
  void useTexture(const TextureSource& source, const std::string& key);
  /// ~texture_from_frame: switches to the frame's material and variant if they differ, and
  /// starts preparing the texture the frame names as the next one.
  void followFrameTexture(const SimFrame& frame);
  TextureSource materialSource(const std::string& material, std::uint32_t variant) const;

  TactileRendererParams params_;
  /// ~trace_file: each frame's stages (its SimFrame taken, its pose known, rendered, image sent).
  enum TraceStage : std::size_t { kTraceReceived, kTracePose, kTraceRendered, kTracePublished };
  FrameTrace trace_;
  std::unique_ptr<TactileRenderer> renderer_;
  std::shared_ptr<TexturedMesh> mesh_;
  std::string texture_key_;  ///< "material/variant" (or the file) being rendered
  /// The latest textures (a dataset revisits few, and each is megabytes) and the next one,
  /// prepared in the background.
  ObjectTextureCache textures_{6};
  std::string prefetch_key_;       ///< the texture frames name as the next one
  TextureSource prefetch_source_;  ///< ... where it comes from
  bool prefetch_done_ = true;      ///< ... and whether it is being or has been prepared
  std::uint64_t rendered_ = 0, missed_ = 0;
  bool answered_any_ = false;
  bool frame_thread_placed_ = false;  ///< ~cpu applied to the frame thread (its first frame)
  std::uint64_t last_answered_frame_ = 0;
  /// The latest answers by frame: repeated when a source offers one of these frames again.
  std::map<std::uint64_t, FrameRendered> recent_answers_;

  ros::NodeHandle nh_;
  tf2_ros::Buffer tf_buffer_;
  /// TF messages, inserted into tf_buffer_ by the frames' thread itself (TransformWaiter).
  ros::CallbackQueue tf_queue_;
  tf2_ros::TransformListener tf_listener_;
  TransformWaiter tf_waiter_{tf_buffer_, tf_queue_};
  image_transport::ImageTransport it_;
  image_transport::Publisher image_pub_;
  ros::Publisher info_pub_, depth_pub_, mask_pub_, rendered_pub_, background_pub_;
  /// <sensor>/markers, advertised only when the sensor model has markers; <sensor>/shear.
  ros::Publisher markers_pub_, shear_pub_;
  /// The frames' queue, served by frame_spinner_; declared before the subscription on it.
  ros::CallbackQueue frame_queue_;
  ros::Subscriber frame_sub_;
  /// ~rehearse_ms: a one-shot timer on frame_queue_ (so on the frames' thread and CPU), armed
  /// after each real-time frame for the next one's due time minus ~rehearse_ms.
  ros::WallTimer rehearsal_timer_;
  struct LastFrame {
    std::uint64_t count = 0;  ///< frames received: a rehearsal after a newer frame is moot
    ros::Time stamp;
    Eigen::Isometry3d object_in_gel = Eigen::Isometry3d::Identity();
    std::int64_t noise_seed = -1;
    std::optional<double> normal_force_n;
    std::optional<ShearLoad> shear;
  } last_frame_;
  std::uint64_t rehearsal_of_ = 0;  ///< last_frame_.count the armed rehearsal is for
  std::uint64_t rehearsals_ = 0;
  void scheduleRehearsal(const ros::Time& stamp, const ros::WallTime& received);
  void rehearse(const ros::WallTimerEvent&);
  // Last: stopped (and joined) first, while everything onFrame uses exists.
  std::unique_ptr<ros::AsyncSpinner> frame_spinner_;
};

}  // namespace norm2tex
