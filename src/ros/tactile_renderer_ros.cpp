#include "tactile_renderer_ros.hpp"

#include <sched.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <optional>
#include <sstream>
#include <thread>

#include <boost/make_shared.hpp>
#include <ros/package.h>
#include <opencv2/core/utility.hpp>

#include "conversions.hpp"
#include "lock_step.hpp"
#include "norm2tex/TactileMarkers.h"
#include "norm2tex/common/error.hpp"
#include "norm2tex/common/memory_reuse.hpp"
#include "norm2tex/mesh/object_mesh.hpp"
#include "norm2tex/materials/material_config.hpp"
#include "norm2tex/render/object_texture.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/sim/gripper_sim_config.hpp"
#include "norm2tex/materials/material_config.hpp"
#include "params.hpp"

namespace norm2tex {
namespace {

using ros_params::badParameter;
using ros_params::readParam;
using ros_params::packageFile;

ros::NodeHandle onQueue(ros::NodeHandle nh, ros::CallbackQueue* queue) {
  nh.setCallbackQueue(queue);
  return nh;
}

}  // namespace

TactileRendererParams readTactileRendererParams(const ros::NodeHandle& pnh) {
  TactileRendererParams p;
  readParam<std::string>(pnh, "sensor_name", p.sensor_name, p.sensor_name);
  if (p.sensor_name.empty() || p.sensor_name.find(' ') != std::string::npos) {
    badParameter("sensor_name", "'" + p.sensor_name + "'", "a topic name such as digit_left");
  }
  readParam<std::string>(pnh, "sensor", p.sensor, packageFile("config/digit.yaml"));
  readParam<std::string>(pnh, "gel_frame", p.gel_frame, p.sensor_name + "_gel");
  readParam<std::string>(pnh, "object_frame", p.object_frame, p.object_frame);
  readParam<std::string>(pnh, "scene", p.scene, packageFile("config/scenes/cube.yaml"));
  readParam<std::string>(pnh, "mesh", p.mesh, "");
  readParam(pnh, "scale", p.scale, p.scale);
  readParam<std::string>(pnh, "normal_map", p.normal_map, "");
  readParam<std::string>(pnh, "convention", p.convention, p.convention);
  readParam<std::string>(pnh, "atlas", p.atlas, "");
  // A material unless a texture file is given. "none" is '' in a word: roslaunch drops empty
  // argument values, so a launch file cannot pass ''.
  readParam<std::string>(pnh, "material", p.material,
                         p.normal_map.empty() && p.atlas.empty() ? "wood" : "");
  if (p.material == ros_params::kNoMaterial) p.material.clear();
  if (!p.material.empty()) {
    p.material_config = ros_params::materialConfigPath(
        p.material, ", or none (the mesh's own texture, or ~normal_map or ~atlas)");
  }
  readParam(pnh, "variant", p.variant, 0);
  if (p.variant < 0) badParameter("variant", std::to_string(p.variant), ">= 0");
  if (!p.material_config.empty()) {
    // A material has variants 0 .. variant_count - 1 (its yaml): one past them is a typo, not
    // a texture of that material.
    const int count = loadMaterialConfig(p.material_config).variant_count;
    if (p.variant >= count) {
      badParameter("variant", std::to_string(p.variant),
                   "[0, " + std::to_string(count - 1) + "] (" + p.material + "'s variant_count " +
                       std::to_string(count) + ")");
    }
  }
  readParam(pnh, "material_seed", p.material_seed, 0);
  if (p.material_seed < 0) badParameter("material_seed", std::to_string(p.material_seed), ">= 0");
  readParam(pnh, "beta", p.beta, p.beta);
  if (!(p.beta < 0.0 || p.beta <= 2.0)) {
    badParameter("beta", std::to_string(p.beta), "[0, 2] mm, or < 0 for the material's");
  }
  readParam<std::string>(pnh, "background", p.background, "");
  readParam(pnh, "noise_seed", p.noise_seed, 0);
  readParam(pnh, "publish_mask", p.publish_mask, false);
  readParam(pnh, "tf_timeout", p.tf_timeout, p.tf_timeout);
  if (!(p.tf_timeout > 0.0 && p.tf_timeout <= 60.0)) {
    badParameter("tf_timeout", std::to_string(p.tf_timeout), "(0, 60] s");
  }
  readParam(pnh, "queue_size", p.queue_size, p.queue_size);
  if (p.queue_size < 1 || p.queue_size > 10000) {
    badParameter("queue_size", std::to_string(p.queue_size), "[1, 10000] messages");
  }
  readParam(pnh, "opencv_threads", p.opencv_threads, p.opencv_threads);
  if (p.opencv_threads < -1 || p.opencv_threads == 0 || p.opencv_threads > 64) {
    badParameter("opencv_threads", std::to_string(p.opencv_threads), "1 to 64, or -1");
  }
  readParam<std::string>(pnh, "frame_topic", p.frame_topic, p.frame_topic);
  readParam<std::string>(pnh, "answer_topic", p.answer_topic, p.answer_topic);
  readParam(pnh, "texture_from_frame", p.texture_from_frame, p.texture_from_frame);
  readParam<std::string>(pnh, "trace_file", p.trace_file, "");
  readParam(pnh, "cpu", p.cpu, p.cpu);
  const int cpus = static_cast<int>(std::thread::hardware_concurrency());
  if (p.cpu < -1 || p.cpu >= std::max(cpus, 1) || p.cpu >= CPU_SETSIZE) {
    badParameter("cpu", std::to_string(p.cpu),
                 "-1 (any CPU) or a CPU of this machine, 0 to " + std::to_string(cpus - 1));
  }
  readParam(pnh, "rehearse_ms", p.rehearse_ms, p.rehearse_ms);
  if (!(p.rehearse_ms >= 0.0 && p.rehearse_ms <= 100.0)) {
    badParameter("rehearse_ms", std::to_string(p.rehearse_ms), "0 (off) to 100 ms");
  }
  if (p.texture_from_frame && p.material.empty()) {
    badParameter("texture_from_frame", "true",
                 "false with ~normal_map or ~atlas (frames name materials)");
  }
  return p;
}

TactileRendererRos::TactileRendererRos(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : params_(readTactileRendererParams(private_nh)),
      trace_(params_.trace_file, {"received", "pose", "rendered", "published"}),
      nh_(nh),
      tf_buffer_(ros::Duration(30.0)),
      // No thread of its own: the frames' thread inserts TF as it needs it (TransformWaiter).
      // No Nagle delay on the small TF and frame messages between separate nodes.
      tf_listener_(tf_buffer_, onQueue(nh, &tf_queue_), false, ros::TransportHints().tcpNoDelay()),
      it_(nh) {
  keepFreedMemoryForReuse();  // frames, bags and textures reuse memory, not fault it in
  SensorModel model = loadSensorModel(params_.sensor);
  if (!params_.background.empty()) model.background_image = params_.background;
  renderer_ = std::make_unique<TactileRenderer>(model);

  std::string mesh_spec = params_.mesh;
  double scale = params_.scale;
  if (mesh_spec.empty()) {
    const GripperSimConfig scene = loadGripperSimConfig(params_.scene);
    mesh_spec = scene.object.mesh;
    scale = scene.object.scale;
  }
  mesh_ = std::make_shared<TexturedMesh>(loadObjectMesh(mesh_spec, scale).mesh);
  TextureSource source;
  source.material_config = params_.material_config;
  source.variant = params_.variant;
  source.seed = static_cast<std::uint64_t>(params_.material_seed);
  source.normal_map = params_.normal_map;
  source.convention = parseNormalConvention(params_.convention);
  source.atlas = params_.atlas;
  ROS_INFO("%s: preparing the texture of %s ...", params_.sensor_name.c_str(), mesh_spec.c_str());
  useTexture(source, params_.material + "/" + std::to_string(params_.variant));
  // Each sensor renders on its own callback thread, the sensors in parallel. OpenCV's pool on
  // top adds a hand-over to other threads per resize, which cost more than they saved on these
  // 320 x 240 images and competed with the other sensor (the start-up bake above still had it).
  if (params_.opencv_threads > 0) cv::setNumThreads(params_.opencv_threads);
  ROS_INFO("%s: rendering %s in %s on %s%s", params_.sensor_name.c_str(),
           params_.object_frame.c_str(), params_.gel_frame.c_str(), params_.frame_topic.c_str(),
           params_.texture_from_frame ? ", texture as each frame names it" : "");

  const std::string& ns = params_.sensor_name;
  const std::uint32_t queue = static_cast<std::uint32_t>(params_.queue_size);
  // The markers before the image: a recorder that finds the image advertised can then ask the
  // master whether this sensor has markers to wait for.
  if (renderer_->model().markers.enabled) {
    markers_pub_ = nh_.advertise<TactileMarkers>(ns + "/markers", queue);
  }
  shear_pub_ = nh_.advertise<sensor_msgs::Image>(ns + "/shear", queue);
  image_pub_ = it_.advertise(ns + "/image_raw", queue);
  info_pub_ = nh_.advertise<sensor_msgs::CameraInfo>(ns + "/camera_info", queue);
  depth_pub_ = nh_.advertise<sensor_msgs::Image>(ns + "/depth", queue);
  if (params_.publish_mask) {
    mask_pub_ = nh_.advertise<sensor_msgs::Image>(ns + "/contact_mask", queue);
  }
  // The no-contact frame (without noise), latched: what background-subtracted datasets subtract.
  background_pub_ = nh_.advertise<sensor_msgs::Image>(ns + "/background", 1, /*latch=*/true);
  std_msgs::Header background_header;
  background_header.frame_id = params_.gel_frame;
  background_pub_.publish(
      ros_conversions::toImageMsg(background_header, renderer_->shader().background()));
  // Frames in order, none dropped by the subscriber: synchronous mode sends one at a time, real
  // time at most a few behind. The answer topic comes last: contact_sim takes it as "ready".
  // They are handled on a thread of this renderer's own, woken by the frame itself: through a
  // nodelet manager's queue a frame waited for two thread hand-overs (its dispatcher, then a
  // worker), ~0.3 ms at the median here. One thread keeps them in order.
  ros::NodeHandle frame_nh(nh_);
  frame_nh.setCallbackQueue(&frame_queue_);
  frame_sub_ = frame_nh.subscribe(params_.frame_topic, 100, &TactileRendererRos::onFrame, this,
                                  ros::TransportHints().tcpNoDelay());
  if (params_.rehearse_ms > 0.0) {
    // Started (and stopped) here: roscpp starts its one wall-timer thread for the process when
    // a timer is first started, and that thread would inherit the frames' thread's ~cpu.
    rehearsal_timer_ = frame_nh.createWallTimer(ros::WallDuration(3600.0),
                                                &TactileRendererRos::rehearse, this,
                                                /*oneshot=*/true, /*autostart=*/true);
    rehearsal_timer_.stop();
  }
  frame_spinner_ = std::make_unique<ros::AsyncSpinner>(1, &frame_queue_);
  frame_spinner_->start();
  // Latched: contact_sim, whenever it subscribes, learns that this renderer is ready.
  rendered_pub_ = nh_.advertise<FrameRendered>(params_.answer_topic, 100, /*latch=*/true);
  FrameRendered ready;
  ready.header.frame_id = params_.gel_frame;
  ready.sensor = params_.sensor_name;
  ready.reason = lock_step::kReady;
  rendered_pub_.publish(ready);
}

TactileRendererRos::~TactileRendererRos() {
  // Disabled queues wake their waiters at once: the frames' spinner would otherwise notice the
  // stop at its next 0.1 s poll, and a manager's shutdown waits for every such thread in turn.
  frame_queue_.disable();
  tf_queue_.disable();
  frame_spinner_.reset();
  if (params_.rehearse_ms > 0.0) {
    // On stdout itself: by now ros::shutdown() has shut rosconsole down.
    std::printf("[ INFO] %s: %lu frames rendered, %lu rehearsed %.1f ms before the next\n",
                params_.sensor_name.c_str(), static_cast<unsigned long>(rendered_),
                static_cast<unsigned long>(rehearsals_), params_.rehearse_ms);
    std::fflush(stdout);
  }
}

void TactileRendererRos::useTexture(const TextureSource& source, const std::string& key) {
  // On this thread, on the renderer's own mesh: a mesh without UVs is unwrapped here (once, at
  // start-up, before any frame).
  const ObjectTextureCache::Lookup lookup =
      textures_.get(key, [&] { return loadObjectTexture(source, *mesh_); });
  const ObjectTexture& texture = *lookup.texture;
  if (!texture.warning.empty() && lookup.origin != ObjectTextureCache::Origin::kCached) {
    ROS_WARN("%s: %s", params_.sensor_name.c_str(), texture.warning.c_str());
  }
  const double beta = params_.beta >= 0.0     ? params_.beta
                      : texture.beta_mm > 0.0 ? texture.beta_mm
                                              : kFileTextureBetaMm;
  const std::string warning =
      renderer_->setObject(mesh_, texture.atlas, texture.atlas ? beta : 0.0);
  if (!warning.empty()) ROS_WARN("%s: %s", params_.sensor_name.c_str(), warning.c_str());
  texture_key_ = key;
  const char* origin = lookup.origin == ObjectTextureCache::Origin::kCached ? "kept"
                       : lookup.origin == ObjectTextureCache::Origin::kPrefetched
                           ? "prepared in the background"
                           : "prepared";
  ROS_INFO("%s: %s, beta %.3f mm, %s, waited %.2f s", params_.sensor_name.c_str(),
           texture.atlas ? texture.description.c_str() : "no texture", texture.atlas ? beta : 0.0,
           origin, lookup.waited_s);
}

TextureSource TactileRendererRos::materialSource(const std::string& material,
                                                 std::uint32_t variant) const {
  TextureSource source;
  source.material_config = ros_params::materialConfigPath(material);
  source.variant = static_cast<int>(variant);
  source.seed = static_cast<std::uint64_t>(params_.material_seed);
  return source;
}

void TactileRendererRos::followFrameTexture(const SimFrame& frame) {
  const std::string key = frame.material + "/" + std::to_string(frame.variant);
  if (key != texture_key_) useTexture(materialSource(frame.material, frame.variant), key);
  if (frame.next_material.empty() || !mesh_->hasUvs()) return;
  const std::string next_key = frame.next_material + "/" + std::to_string(frame.next_variant);
  if (next_key == texture_key_) return;
  if (next_key != prefetch_key_) {  // resolved once per texture, not per frame (rospack)
    prefetch_key_ = next_key;
    prefetch_done_ = false;
    try {
      prefetch_source_ = materialSource(frame.next_material, frame.next_variant);
    } catch (const Error&) {
      prefetch_done_ = true;  // an unknown material: reported when a frame names it as its own
      return;
    }
  }
  if (prefetch_done_) return;
  // The background works on a copy: the renderer keeps reading its mesh meanwhile. Another
  // preparation under way: tried again with the next frame.
  std::shared_ptr<const TexturedMesh> mesh = mesh_;
  prefetch_done_ = textures_.prefetch(next_key, [source = prefetch_source_, mesh] {
    TexturedMesh copy = *mesh;
    return loadObjectTexture(source, copy);
  }) || textures_.contains(next_key);
}

bool TactileRendererRos::anyoneListens() const {
  return image_pub_.getNumSubscribers() > 0 || info_pub_.getNumSubscribers() > 0 ||
         depth_pub_.getNumSubscribers() > 0 || (mask_pub_ && mask_pub_.getNumSubscribers() > 0) ||
         (markers_pub_ && markers_pub_.getNumSubscribers() > 0) ||
         shear_pub_.getNumSubscribers() > 0;
}

void TactileRendererRos::placeFrameThread() {
  // ~cpu: the two sensors' frame threads wake for the same SimFrame microseconds apart. Left
  // to the scheduler, the second was often woken onto the CPU where the first had started,
  // preempted it, and the first then stayed there (cache-hot) while the other CPU idled: in a
  // third of the frames the two renders ran one after the other (+2 ms). One CPU each keeps
  // them in parallel.
  frame_thread_placed_ = true;
  if (params_.cpu < 0) return;
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(params_.cpu, &set);
  if (sched_setaffinity(0, sizeof set, &set) != 0) {
    ROS_WARN("%s: ~cpu %d: %s", params_.sensor_name.c_str(), params_.cpu, std::strerror(errno));
  }
}

bool TactileRendererRos::answerAgain(const SimFrame& frame) {
  if (!frame.acknowledge || !answered_any_ || frame.frame > last_answered_frame_) return false;
  // Offered again (a source re-offers frames it has no answer to from everyone): answer again,
  // never render twice; a frame older than the answers kept is ignored.
  const auto it = recent_answers_.find(frame.frame);
  if (it != recent_answers_.end() && it->second.header.stamp == frame.header.stamp) {
    rendered_pub_.publish(it->second);
  }
  return true;
}

Eigen::Isometry3d TactileRendererRos::objectInGelAt(const ros::Time& stamp) {
  // The pose at exactly this stamp: wait (wall clock: simulated time may stand still) for TF,
  // never extrapolate or take a stale pose.
  std::string why;
  if (!tf_waiter_.wait(params_.gel_frame, params_.object_frame, stamp, params_.tf_timeout, &why)) {
    if (!ros::ok()) throw Error("shutting down");
    std::ostringstream reason;
    reason << "TF " << params_.object_frame << " -> " << params_.gel_frame << " at " << stamp
           << " not available within ~tf_timeout = " << params_.tf_timeout << " s (" << why
           << ")";
    throw Error(reason.str());
  }
  return ros_conversions::fromTransformMsg(
      tf_buffer_.lookupTransform(params_.gel_frame, params_.object_frame, stamp).transform);
}

std::optional<double> TactileRendererRos::normalForceIn(const SimFrame& frame) const {
  // The gel's normal force when the source knows it (contact_sim), for the texture's
  // conformity; else the renderer takes the gel law's force for the press.
  for (std::size_t i = 0; i < frame.sensors.size() && i < frame.normal_force.size(); ++i) {
    if (frame.sensors[i] == params_.sensor_name) return frame.normal_force[i];
  }
  return std::nullopt;
}

void TactileRendererRos::renderAndPublish(const SimFrame& frame) {
  const Eigen::Isometry3d object_in_gel = objectInGelAt(frame.header.stamp);
  trace_.mark(kTracePose);
  const std::int64_t noise_seed = params_.noise_seed < 0
                                      ? -1
                                      : static_cast<std::int64_t>(params_.noise_seed) * 1000003 +
                                            static_cast<std::int64_t>(frame.frame);
  const std::optional<double> normal_force_n = normalForceIn(frame);
  // The tangential load moves the gel's surface sideways: what the markers show and /shear
  // publishes. Without either (a DIGIT's gel has no markers) the image is the same without it,
  // so the shear stage is skipped.
  const bool shear_wanted = shear_pub_.getNumSubscribers() > 0;
  std::optional<ShearLoad> shear;
  if (markers_pub_ || shear_wanted) {
    shear = ros_conversions::shearLoadIn(frame, params_.sensor_name);
  }
  const TactileFrame& rendered =
      renderer_->render(object_in_gel, noise_seed, normal_force_n, shear);
  trace_.mark(kTraceRendered);
  if (params_.rehearse_ms > 0.0 && !frame.acknowledge) {
    last_frame_.object_in_gel = object_in_gel;
    last_frame_.noise_seed = noise_seed;
    last_frame_.normal_force_n = normal_force_n;
    last_frame_.shear = shear;
  }
  std_msgs::Header header;
  header.stamp = frame.header.stamp;
  header.frame_id = params_.gel_frame;
  // The image always (one per frame); the others are built only for someone (a 300 kB depth
  // copy per frame is not free).
  image_pub_.publish(ros_conversions::toImageMsg(header, rendered.image));
  trace_.mark(kTracePublished);
  if (info_pub_.getNumSubscribers() > 0) {
    info_pub_.publish(ros_conversions::toCameraInfo(header, renderer_->model()));
  }
  if (depth_pub_.getNumSubscribers() > 0) {
    depth_pub_.publish(ros_conversions::toImageMsg(header, rendered.depthMetres()));
  }
  if (mask_pub_ && mask_pub_.getNumSubscribers() > 0) {
    mask_pub_.publish(ros_conversions::toImageMsg(header, rendered.contact_mask));
  }
  // Every frame when the sensor has markers (a recorder counts on one per image).
  if (markers_pub_ && rendered.shear) {
    const MarkerOptions& grid = renderer_->model().markers;
    markers_pub_.publish(boost::make_shared<TactileMarkers>(
        ros_conversions::toMarkersMsg(header, grid.rows, grid.cols, *rendered.shear)));
  }
  if (shear_wanted) {
    // The field at every pixel (a full-resolution upsample of the cells): only for listeners.
    // No load, no markers: the surface has not moved.
    const cv::Size size = renderer_->model().imageSize();
    shear_pub_.publish(ros_conversions::toImageMsg(
        header, rendered.shear ? cv::Mat(rendered.shear->displacementMetres(size))
                               : cv::Mat(cv::Mat2f::zeros(size))));
  }
}

void TactileRendererRos::keepAnswer(const FrameRendered& answer) {
  rendered_pub_.publish(answer);
  recent_answers_[answer.frame] = answer;
  if (recent_answers_.size() > 256) recent_answers_.erase(recent_answers_.begin());
  last_answered_frame_ = answer.frame;
  answered_any_ = true;
}

void TactileRendererRos::onFrame(const SimFrame::ConstPtr& frame) {
  const ros::WallTime received = ros::WallTime::now();
  ++last_frame_.count;
  if (!frame_thread_placed_) placeFrameThread();
  if (trace_.enabled()) {
    trace_.begin(frame->header.stamp);
    trace_.mark(kTraceReceived);
  }
  struct EndTrace {
    FrameTrace& trace;
    ~EndTrace() { trace.end(); }
  } end_trace{trace_};
  // Real time: skip the work when nobody listens (but keep the TF queue short). Synchronous:
  // every frame is rendered.
  if (!frame->acknowledge && !anyoneListens()) {
    tf_waiter_.insertReceived();
    return;
  }
  if (answerAgain(*frame)) return;
  FrameRendered answer;
  answer.header.stamp = frame->header.stamp;
  answer.header.frame_id = params_.gel_frame;
  answer.sensor = params_.sensor_name;
  answer.frame = frame->frame;
  try {
    if (params_.texture_from_frame) followFrameTexture(*frame);
    renderAndPublish(*frame);
    answer.published = true;
    ++rendered_;
  } catch (const Error& e) {
    ++missed_;
    answer.published = false;
    answer.reason = e.what();
    ROS_WARN_THROTTLE(1.0, "%s: frame %lu has no image (%lu of %lu frames so far): %s",
                      params_.sensor_name.c_str(), static_cast<unsigned long>(frame->frame),
                      static_cast<unsigned long>(missed_),
                      static_cast<unsigned long>(missed_ + rendered_), e.what());
  }
  if (params_.rehearse_ms > 0.0 && !frame->acknowledge && answer.published) {
    scheduleRehearsal(frame->header.stamp, received);
  }
  if (frame->acknowledge) keepAnswer(answer);
}

void TactileRendererRos::scheduleRehearsal(const ros::Time& stamp, const ros::WallTime& received) {
  // The next frame is due one period after this one arrived; the period is the stamps' step
  // (real time: simulated and wall time advance together). Not known before the second frame.
  const ros::Time previous = last_frame_.stamp;
  last_frame_.stamp = stamp;
  if (previous.isZero() || stamp <= previous) return;
  const double period_s = (stamp - previous).toSec();
  if (period_s > 1.0) return;  // a pause, not a rate
  const double delay_s =
      (received - ros::WallTime::now()).toSec() + period_s - params_.rehearse_ms * 1e-3;
  if (delay_s <= 0.0) return;  // the frame ran late: the next one is too close to rehearse
  rehearsal_of_ = last_frame_.count;
  rehearsal_timer_.stop();
  rehearsal_timer_.setPeriod(ros::WallDuration(delay_s));
  rehearsal_timer_.start();
}

void TactileRendererRos::rehearse(const ros::WallTimerEvent&) {
  // On the frames' thread: no frame can be rendering now. A newer frame than the one armed for
  // means the rehearsal came too late to matter.
  if (rehearsal_of_ != last_frame_.count) return;
  try {
    renderer_->render(last_frame_.object_in_gel, last_frame_.noise_seed,
                      last_frame_.normal_force_n, last_frame_.shear);
    if (rehearsals_++ == 0) {
      ROS_INFO("%s: rehearsing each real-time frame %.1f ms before the next one is due",
               params_.sensor_name.c_str(), params_.rehearse_ms);
    }
  } catch (const Error& e) {
    ROS_DEBUG("%s: rehearsal skipped: %s", params_.sensor_name.c_str(), e.what());
  }
}

}  // namespace norm2tex
