// Bindings of any hand: the hand yaml (HandConfig), HandSimConfig, HandSim and TactileHand.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "norm2tex/sim/gripper_sim.hpp"
#include "norm2tex/sim/hand_config.hpp"
#include "norm2tex/sim/hand_sim.hpp"
#include "norm2tex/sim/tactile_hand.hpp"
#include "numpy_conversions.hpp"

namespace norm2tex {
namespace python {
namespace {

using Release = py::call_guard<py::gil_scoped_release>;

/// A sensor of the hand by index (the hand yaml's order) or name.
int sensorFrom(const HandSim& sim, const py::handle& sensor) {
  std::string names;
  for (int s = 0; s < sim.sensorCount(); ++s) names += (s ? ", " : "") + sim.sensor(s).name;
  if (py::isinstance<py::str>(sensor)) {
    const std::string name = sensor.cast<std::string>();
    for (int s = 0; s < sim.sensorCount(); ++s) {
      if (sim.sensor(s).name == name) return s;
    }
    throw py::key_error("sensor '" + name + "' is not in the hand; its sensors: " + names);
  }
  if (py::isinstance<py::bool_>(sensor) || !py::isinstance<py::int_>(sensor)) {
    throw py::type_error("a sensor is its index or its name (" + names + ")");
  }
  const long index = sensor.cast<long>();
  if (index < 0 || index >= sim.sensorCount()) {
    throw py::index_error("sensor index " + std::to_string(index) + "; valid: [0, " +
                          std::to_string(sim.sensorCount() - 1) + "] (" + names + ")");
  }
  return static_cast<int>(index);
}

/// Joint indices of `names` (None: the actuated joints).
std::vector<int> jointsFrom(const HandSim& sim, const py::object& names) {
  const std::vector<std::string> list =
      names.is_none() ? sim.actuatedJoints() : names.cast<std::vector<std::string>>();
  std::vector<int> out;
  for (const std::string& name : list) {
    const int j = sim.description().jointIndex(name);
    if (j < 0) {
      std::string all;
      for (const HandJoint& joint : sim.description().joints) all += (all.empty() ? "" : ", ") + joint.name;
      throw py::key_error("unknown joint '" + name + "'; the hand's joints: " + all);
    }
    out.push_back(j);
  }
  return out;
}

py::array_t<double> perJoint(const std::vector<int>& joints, const std::vector<double>& values) {
  py::array_t<double> out(static_cast<Py_ssize_t>(joints.size()));
  for (std::size_t i = 0; i < joints.size(); ++i) out.mutable_at(i) = values[joints[i]];
  return out;
}

std::optional<Eigen::Isometry3d> optionalPose(const py::object& pose, const std::string& what) {
  if (pose.is_none()) return std::nullopt;
  return poseFromPython(pose, what);
}

/// (names, values) from a dict {name: value} or two sequences.
std::pair<std::vector<std::string>, std::vector<double>> namedValues(const py::object& names,
                                                                     const py::object& values) {
  if (py::isinstance<py::dict>(names)) {
    if (!values.is_none()) throw py::type_error("give a dict {joint: position}, or names and positions");
    std::vector<std::string> n;
    std::vector<double> v;
    for (const auto& item : names.cast<py::dict>()) {
      n.push_back(item.first.cast<std::string>());
      v.push_back(item.second.cast<double>());
    }
    return {n, v};
  }
  if (values.is_none()) throw py::type_error("positions missing: give names and positions, or a dict");
  const py::array_t<double, py::array::c_style | py::array::forcecast> array(values);
  return {names.cast<std::vector<std::string>>(),
          std::vector<double>(array.data(), array.data() + array.size())};
}

HandConfig handFrom(const py::object& hand) {
  if (py::isinstance<HandConfig>(hand)) return hand.cast<HandConfig>();
  if (py::isinstance<py::str>(hand)) return loadHandConfig(hand.cast<std::string>());
  throw py::type_error("hand: a HandConfig or the path of a hand yaml");
}

}  // namespace

void bindHand(py::module& m) {
  py::class_<SensorMount>(m, "SensorMount", "A DIGIT on a link of the hand (a hand yaml's sensors entry).")
      .def_readonly("name", &SensorMount::name, "topic namespace and TF frame prefix")
      .def_readonly("link", &SensorMount::link)
      .def_property_readonly("digit_in_link", [](const SensorMount& s) { return poseToNumpy(s.digit_in_link); },
                             "the DIGIT's TACTO frame in the link frame (4x4, m)")
      .def_readonly("sensor_yaml", &SensorMount::sensor_yaml, "its own sensor model ('' = the shared one)")
      .def("__repr__", [](const SensorMount& s) { return "<SensorMount " + s.name + " on " + s.link + ">"; });

  py::class_<HandConfig>(m, "HandConfig", "A hand yaml (docs/hands.md): the URDF, its pose, its DIGITs, its drives.")
      .def_static("load", &loadHandConfig, py::arg("yaml_path"),
                  "Reads a hand yaml; raises norm2tex.Error naming the file and the key at fault.")
      .def_readwrite("urdf_path", &HandConfig::urdf_path)
      .def_readwrite("root_link", &HandConfig::root_link)
      .def_property("base_pose", [](const HandConfig& h) { return poseToNumpy(h.base_pose); },
                    [](HandConfig& h, const py::object& pose) { h.base_pose = poseFromPython(pose, "base_pose"); },
                    "the root link's pose in the world (4x4, m)")
      .def_readonly("sensors", &HandConfig::sensors)
      .def_property_readonly("sensor_names", [](const HandConfig& h) {
        std::vector<std::string> names;
        for (const SensorMount& s : h.sensors) names.push_back(s.name);
        return names;
      })
      .def_readwrite("initial_positions", &HandConfig::initial_positions)
      .def_readonly("gripper_joints", &HandConfig::gripper_joints,
                    "the joints set_opening drives (empty: not a two-finger hand)");

  py::class_<HandSimConfig>(m, "HandSimConfig",
                            "Everything a HandSim is made of: the hand, the object and its pose, "
                            "physics, gel law and pad.")
      .def(py::init([](const py::object& hand, const GripperSimConfig* scene) {
             HandSimConfig c;
             c.hand = handFrom(hand);
             if (scene) {
               // As makeHandSimConfig: a scene yaml's object, physics, gel law and gel pad.
               c.object = scene->object;
               c.physics = scene->physics;
               c.gel_law = scene->gel_law;
               c.gel_width_m = scene->gel_width_m;
               c.gel_height_m = scene->gel_height_m;
               c.gel_thickness_m = scene->gel_thickness_m;
             }
             return c;
           }),
           py::arg("hand"), py::arg("scene") = nullptr,
           "hand: a HandConfig or a hand yaml's path; scene: a SceneConfig whose object, physics "
           "and gel law to use (None: the defaults, a 30 mm cube).")
      .def_readwrite("hand", &HandSimConfig::hand)
      .def_readwrite("object", &HandSimConfig::object)
      .def_property("object_pose", [](const HandSimConfig& c) { return poseToNumpy(c.object_pose); },
                    [](HandSimConfig& c, const py::object& pose) {
                      c.object_pose = poseFromPython(pose, "object_pose");
                    },
                    "the object frame in the world at construction and reset (4x4, m)")
      .def_readwrite("physics", &HandSimConfig::physics)
      .def_readwrite("gel_law", &HandSimConfig::gel_law);

  py::class_<HandSim>(
      m, "HandSim",
      "Any hand from its URDF with DIGITs on any links, holding an object, on Bullet (docs/hands.md). "
      "Position-controlled joints; deterministic. Sensors are named by index or name.")
      .def(py::init([](const HandSimConfig& config, const SensorModel* sensor) {
             HandSimConfig c = config;
             if (sensor) {
               c.gel_width_m = sensor->gel_pad_width_mm * 1e-3;
               c.gel_height_m = sensor->gel_pad_height_mm * 1e-3;
               c.gel_thickness_m = sensor->gel_thickness_mm * 1e-3;
             }
             py::gil_scoped_release release;
             return std::make_unique<HandSim>(c);
           }),
           py::arg("config"), py::arg("sensor") = nullptr,
           "From a HandSimConfig; with a SensorModel the gel pads are the sensor's.")
      .def_property_readonly("name", [](const HandSim& s) { return s.description().name; })
      .def_property_readonly("warnings", &HandSim::warnings, "what loading changed or noticed")
      .def_property_readonly("urdf", [](const HandSim& s) { return s.description().urdf_xml; })
      .def_property_readonly("link_names", [](const HandSim& s) {
        std::vector<std::string> names;
        for (const HandLink& l : s.description().links) names.push_back(l.name);
        return names;
      })
      .def_property_readonly("joint_names", [](const HandSim& s) {
        std::vector<std::string> names;
        for (const HandJoint& j : s.description().joints) names.push_back(j.name);
        return names;
      }, "every joint, fixed and mimic ones too")
      .def_property_readonly("actuated_joints", &HandSim::actuatedJoints,
                             "the joints a command may name: movable and not mimic")
      .def("joint_positions", [](const HandSim& s, const py::object& joints) {
             return perJoint(jointsFrom(s, joints), s.jointPositions());
           }, py::arg("joints") = py::none(),
           "Positions (rad or m) of the named joints (None: actuated_joints), float64.")
      .def("joint_targets", [](const HandSim& s, const py::object& joints) {
             return perJoint(jointsFrom(s, joints), s.jointTargets());
           }, py::arg("joints") = py::none(), "The drives' targets, as joint_positions.")
      .def("joint_loads", [](const HandSim& s, const py::object& joints) {
             return perJoint(jointsFrom(s, joints), s.jointLoads());
           }, py::arg("joints") = py::none(),
           "The generalised force of the contacts on each joint (N or N m), as joint_positions.")
      .def("joint_limits", [](const HandSim& s, const py::object& joints) {
             const std::vector<int> js = jointsFrom(s, joints);
             py::array_t<double> lower(static_cast<Py_ssize_t>(js.size())), upper(static_cast<Py_ssize_t>(js.size()));
             for (std::size_t i = 0; i < js.size(); ++i) {
               lower.mutable_at(i) = s.description().joints[js[i]].lower;
               upper.mutable_at(i) = s.description().joints[js[i]].upper;
             }
             return py::make_tuple(lower, upper);
           }, py::arg("joints") = py::none(),
           "(lower, upper) URDF limits of the named joints (None: actuated_joints); +-inf for "
           "continuous joints.")
      .def("set_joint_targets",
           [](HandSim& s, const py::object& names, const py::object& positions) {
             auto [n, v] = namedValues(names, positions);
             return s.setJointTargets(n, v);
           },
           py::arg("names"), py::arg("positions") = py::none(),
           "Targets for named actuated joints (names and positions, or a dict {name: position}); "
           "the others keep theirs; stops a trajectory. Out-of-limit targets are clamped: returns "
           "the names clamped. Raises norm2tex.Error (nothing changed) for an unknown, fixed or "
           "mimic joint, a size mismatch or a value that is not finite.")
      .def("set_trajectory",
           [](HandSim& s, const std::vector<std::string>& names, const std::vector<double>& times_s,
              const std::vector<std::vector<double>>& positions) {
             JointTrajectoryCommand t;
             t.joint_names = names;
             t.times_s = times_s;
             t.positions = positions;
             return s.setTrajectory(t);
           },
           py::arg("joint_names"), py::arg("times_s"), py::arg("positions"),
           "Follows a trajectory from now (as trajectory_msgs/JointTrajectory): per point its "
           "time from the start (s, increasing) and one position per joint name, reached "
           "linearly. Errors and clamping as set_joint_targets.")
      .def("set_opening", &HandSim::setOpening, py::arg("opening"),
           "The hand yaml's gripper joints to opening 0 (closed) ... 1 (open).")
      .def("set_base_pose", [](HandSim& s, const py::object& pose) {
             s.setBasePose(poseFromPython(pose, "base pose"));
           }, py::arg("pose"), "Moves the hand's root (4x4 or (xyz, quaternion xyzw), m).")
      .def_property_readonly("base_pose", [](const HandSim& s) { return poseToNumpy(s.basePose()); })
      .def("reset", [](HandSim& s, const py::object& object_pose) {
             const std::optional<Eigen::Isometry3d> pose = optionalPose(object_pose, "object_pose");
             py::gil_scoped_release release;
             s.reset(pose ? &*pose : nullptr);
           }, py::arg("object_pose") = py::none(),
           "Starts again: joints, drives and root at their initial values, the object at rest at "
           "object_pose (None: the last reset's, else the config's).")
      .def("reset_object", [](HandSim& s, const py::object& pose, bool gravity) {
             s.resetObject(poseFromPython(pose, "object pose"), gravity);
           }, py::arg("pose"), py::arg("gravity") = true, "Puts the object at rest at pose.")
      .def("set_object_gravity", &HandSim::setObjectGravity, py::arg("on"))
      .def("step", &HandSim::step, py::arg("ticks") = 1, Release(),
           "Advances `ticks` physics ticks of tick_seconds each.")
      .def_property_readonly("tick_seconds", &HandSim::tickSeconds)
      .def_property_readonly("ticks", &HandSim::ticks)
      .def_property_readonly("sensor_count", &HandSim::sensorCount)
      .def_property_readonly("sensor_names", [](const HandSim& s) {
        std::vector<std::string> names;
        for (int i = 0; i < s.sensorCount(); ++i) names.push_back(s.sensor(i).name);
        return names;
      }, "the hand yaml's sensors, in order")
      .def("contact", [](const HandSim& s, const py::object& sensor) {
             return contactDict(s.contact(sensorFrom(s, sensor)));
           }, py::arg("sensor"),
           "What a gel feels: in_contact, normal_force_n (N), shear_force_n (N, gel frame), "
           "pressure_centre_m (gel x, y, m), twist_moment_nm (N m, about the gel's +z "
           "through that centre), penetration_m, too_deep, object_in_gel (4x4).")
      .def("gel_in_world", [](const HandSim& s, const py::object& sensor) {
             return poseToNumpy(s.gelInWorld(sensorFrom(s, sensor)));
           }, py::arg("sensor"), "the sensor's gel frame in the world (4x4, m)")
      .def("link_in_world", [](const HandSim& s, const std::string& link) {
             const int l = s.description().linkIndex(link);
             if (l < 0) throw py::key_error("link '" + link + "' is not in the hand");
             return poseToNumpy(s.linkInWorld(l));
           }, py::arg("link"))
      .def("object_in_world", [](const HandSim& s) { return poseToNumpy(s.objectInWorld()); })
      .def_property_readonly("collision", [](const HandSim& s) {
        return py::make_tuple(s.collision().kind, s.collision().parts);
      }, "(kind, convex parts) the object collides as");

  py::class_<TactileHandOptions> hand_options(
      m, "TactileHandOptions",
      "How a TactileHand runs: TactileGripperOptions' fields but the episode's, same meanings.");
  bindTactileOptions(hand_options)
      .def_readwrite("render_threads", &TactileHandOptions::render_threads,
                     "threads the sensors render on (the same frames whatever the count): 1 one "
                     "after another, 0 one per core");

  py::class_<TactileHand>(
      m, "TactileHand",
      "A HandSim and one DIGIT renderer per mounted sensor, advanced a sensor frame at a time "
      "(whole physics ticks per frame); what hand_sim.launch's nodes compute, in-process. "
      "Images are copies (rows, cols, 3) uint8 bgr8.")
      .def(py::init([](const HandSimConfig& config, const SensorModel& sensor,
                       const TactileHandOptions& options) {
             py::gil_scoped_release release;
             return std::make_unique<TactileHand>(config, sensor, options);
           }),
           py::arg("config"), py::arg("sensor"), py::arg("options") = TactileHandOptions(),
           "Every sensor renders with `sensor` unless the hand yaml gives it its own; starts "
           "with a reset().")
      .def("reset", [](TactileHand& h, const py::object& object_pose) {
             const std::optional<Eigen::Isometry3d> pose = optionalPose(object_pose, "object_pose");
             py::gil_scoped_release release;
             h.reset(pose);
           }, py::arg("object_pose") = py::none(),
           "HandSim.reset, padded to whole frames, then every sensor renders.")
      .def("step", &TactileHand::step, py::arg("frames") = 1, Release(),
           "Advances `frames` sensor frames and renders every sensor at the last.")
      .def_property_readonly("sim", [](TactileHand& h) -> HandSim& { return h.sim(); },
                             py::return_value_policy::reference_internal,
                             "its HandSim (commands, joints, contacts; valid while the hand lives)")
      .def_property_readonly("sensor_count", &TactileHand::sensorCount)
      .def_property_readonly("sensor_names", [](const TactileHand& h) {
        std::vector<std::string> names;
        for (int i = 0; i < h.sensorCount(); ++i) names.push_back(h.sensorName(i));
        return names;
      })
      .def("frame", [](const TactileHand& h, const py::object& sensor) {
             return toNumpy(h.frame(sensorFrom(h.sim(), sensor)).image);
           }, py::arg("sensor"), "the latest image of a sensor, (rows, cols, 3) uint8 bgr8")
      .def("images", [](const TactileHand& h) {
             py::dict out;
             for (int i = 0; i < h.sensorCount(); ++i) out[py::str(h.sensorName(i))] = toNumpy(h.frame(i).image);
             return out;
           }, "every sensor's latest image by name")
      .def("markers", [](const TactileHand& h) {
             py::dict out;
             for (int i = 0; i < h.sensorCount(); ++i) {
               const auto& shear = h.frame(i).shear;
               const Py_ssize_t count = shear ? static_cast<Py_ssize_t>(shear->markers.size()) : 0;
               py::array_t<float> moved({count, Py_ssize_t{2}});
               for (Py_ssize_t k = 0; k < count; ++k) {
                 moved.mutable_at(k, 0) = shear->markers[k].displacement_mm.x;
                 moved.mutable_at(k, 1) = shear->markers[k].displacement_mm.y;
               }
               out[py::str(h.sensorName(i))] = moved;
             }
             return out;
           }, "every sensor's markers' displacement on its gel by name, (markers, 2) float32 mm "
              "(gel frame); 0 wide for a sensor without markers")
      .def("depth", [](const TactileHand& h, const py::object& sensor) {
             return toNumpy(h.frame(sensorFrom(h.sim(), sensor)).depthMetres());
           }, py::arg("sensor"), "(rows, cols) float32 gel deformation, metres")
      .def("contact_mask", [](const TactileHand& h, const py::object& sensor) {
             return toNumpy(h.frame(sensorFrom(h.sim(), sensor)).contact_mask);
           }, py::arg("sensor"), "(rows, cols) uint8, 255 in contact")
      .def("background", [](const TactileHand& h, const py::object& sensor) {
             return toNumpy(h.background(sensorFrom(h.sim(), sensor)));
           }, py::arg("sensor"), "the no-contact frame without noise, (rows, cols, 3) uint8")
      .def("object_in_gel", [](const TactileHand& h, const py::object& sensor) {
             return poseToNumpy(h.objectInGel(sensorFrom(h.sim(), sensor)));
           }, py::arg("sensor"), "the object frame in the sensor's gel frame (4x4, m)")
      .def("set_noise_seed", &TactileHand::setNoiseSeed, py::arg("noise_seed"),
           "from the next frame on (< 0: none)")
      .def_property_readonly("frame_index", &TactileHand::frameIndex)
      .def_property_readonly("ticks_per_frame", &TactileHand::ticksPerFrame)
      .def_property_readonly("frame_seconds", &TactileHand::frameSeconds)
      .def_property_readonly("beta_mm", &TactileHand::betaMm)
      .def_property_readonly("friction", &TactileHand::friction);
}

}  // namespace python
}  // namespace norm2tex
