// Bindings of the simulation: the scene config, GripperSim, TactileGripper and its batch.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "norm2tex/gel/gel_law.hpp"
#include "norm2tex/sim/gripper_sim.hpp"
#include "norm2tex/sim/tactile_gripper.hpp"
#include "norm2tex/sim/tactile_gripper_batch.hpp"
#include "numpy_conversions.hpp"

namespace norm2tex {
namespace python {
namespace {

using Release = py::call_guard<py::gil_scoped_release>;

Finger fingerFrom(const std::string& name) {
  if (name == "left" || name == "digit_left") return Finger::kLeft;
  if (name == "right" || name == "digit_right") return Finger::kRight;
  throw py::value_error("finger '" + name + "'; valid: left, right");
}

py::dict episodeDict(const EpisodeStart& s) {
  py::dict out;
  out["episode"] = s.episode;
  out["seed"] = s.seed;
  out["height_offset_m"] = s.height_offset_m;
  out["grasp_opening"] = s.grasp_opening;
  return out;
}

std::optional<double> offsetFrom(const py::object& value) {
  if (value.is_none()) return std::nullopt;
  return value.cast<double>();
}

/// The frames of every gripper of a batch for one sensor, stacked: (N, rows, cols, 3) uint8.
py::array stackImages(const TactileGripperBatch& batch, Finger finger) {
  const cv::Mat3b& first = batch.gripper(0).frame(finger).image;
  const Py_ssize_t n = batch.size(), rows = first.rows, cols = first.cols;
  py::array_t<std::uint8_t> out({n, rows, cols, Py_ssize_t{3}});
  const std::size_t bytes = static_cast<std::size_t>(rows * cols * 3);
  for (int i = 0; i < batch.size(); ++i) {
    const cv::Mat3b& image = batch.gripper(i).frame(finger).image;
    const cv::Mat3b rows = image.isContinuous() ? image : image.clone();  // one block to copy
    std::memcpy(out.mutable_data(i), rows.data, bytes);
  }
  return out;
}

}  // namespace

namespace {

/// A command mode from Python (an int or a norm2tex.OpeningCommand); ValueError for others.
OpeningCommand openingCommand(int mode) {
  if (mode < 0 || mode > 2) {
    throw py::value_error("command mode " + std::to_string(mode) +
                          "; valid: 0 ABSOLUTE, 1 DELTA, 2 KEEP (norm2tex.envs.commands)");
  }
  return static_cast<OpeningCommand>(mode);
}

}  // namespace

void bindSim(py::module& m) {
  py::enum_<OpeningCommand>(m, "OpeningCommand",
                            "A command mode of TactileGripperBatch.step (the values of "
                            "GripperCommand.msg's ABSOLUTE and DELTA, then KEEP)")
      .value("ABSOLUTE", OpeningCommand::kAbsolute)
      .value("DELTA", OpeningCommand::kDelta)
      .value("KEEP", OpeningCommand::kKeep);
  py::class_<GelLaw>(m, "GelLaw",
                     "The gel's force-indentation law (scene yaml gel.law): normal force of a "
                     "contact from its deepest indentation, piecewise power law through points.")
      .def(py::init<std::vector<std::pair<double, double>>>(), py::arg("points"),
           "(indentation m, force N) pairs, strictly increasing in both.")
      .def_static("default", &GelLaw::taximDefault, "the scenes' default law")
      .def("force", &GelLaw::force, py::arg("indentation_m"), "N at an indentation (m)")
      .def("indentation", &GelLaw::indentation, py::arg("force_n"),
           "m at a force (N): the inverse of force()")
      .def_property_readonly("points", &GelLaw::points);
  py::class_<GripperOptions>(m, "GripperOptions", "scene yaml section gripper")
      .def_readwrite("hand_yaml", &GripperOptions::hand_yaml,
                     "a two-finger hand yaml of your own (gripper.hand), '' for the built-in "
                     "gripper; with a hand, GripperSim.config's other fields are the hand's")
      .def_readwrite("base_height_m", &GripperOptions::base_height_m)
      .def_readwrite("min_gap_m", &GripperOptions::min_gap_m, "gel gap at opening 0, m")
      .def_readwrite("max_gap_m", &GripperOptions::max_gap_m, "gel gap at opening 1, m")
      .def_readwrite("max_force_n", &GripperOptions::max_force_n, "the fingers' force limit, N")
      .def_readwrite("max_speed_m_s", &GripperOptions::max_speed_m_s, "finger speed, m/s")
      .def_readwrite("stiffness_n_per_m", &GripperOptions::stiffness_n_per_m,
                     "each finger's drive in series with its gel, N/m (0: rigid)");
  py::class_<ObjectOptions>(m, "ObjectOptions", "scene yaml section object")
      .def_readwrite("name", &ObjectOptions::name)
      .def_readwrite("mesh", &ObjectOptions::mesh, "mesh file or primitive ('box:30x30x30')")
      .def_readwrite("scale", &ObjectOptions::scale, "mesh units to metres")
      .def_readwrite("mass_kg", &ObjectOptions::mass_kg)
      .def_readwrite("collision", &ObjectOptions::collision, "auto, box, hull, decomposition")
      .def_readwrite("friction", &ObjectOptions::friction, "Coulomb coefficient against the gel")
      .def_readwrite("material", &ObjectOptions::material, "label only");
  py::class_<PhysicsOptions>(m, "PhysicsOptions", "scene yaml section physics")
      .def_readwrite("rate_hz", &PhysicsOptions::rate_hz)
      .def_readwrite("solver_iterations", &PhysicsOptions::solver_iterations)
      .def_readwrite("gravity_m_s2", &PhysicsOptions::gravity_m_s2);
  py::class_<EpisodeOptions>(m, "EpisodeOptions", "scene yaml section episode")
      .def_readwrite("height_offset_low_m", &EpisodeOptions::height_offset_low_m)
      .def_readwrite("height_offset_high_m", &EpisodeOptions::height_offset_high_m)
      .def_readwrite("grasp_opening", &EpisodeOptions::grasp_opening,
                     "< 0: close until the gels touch, then to grasp_indentation_m / grasp_force_n")
      .def_readwrite("grasp_indentation_m", &EpisodeOptions::grasp_indentation_m)
      .def_readwrite("grasp_force_n", &EpisodeOptions::grasp_force_n)
      .def_readwrite("settle_s", &EpisodeOptions::settle_s);
  py::class_<GripperSimConfig>(m, "SceneConfig",
                               "A gripper scene (config/scenes/*.yaml): gripper, object, physics, "
                               "episode.")
      .def(py::init<>())
      .def_static("load", &loadGripperSimConfig, py::arg("yaml_path"),
                  "Reads a scene yaml; raises norm2tex.Error naming the file and key at fault.")
      .def_readwrite("gripper", &GripperSimConfig::gripper)
      .def_readwrite("object", &GripperSimConfig::object)
      .def_readwrite("physics", &GripperSimConfig::physics)
      .def_readwrite("episode", &GripperSimConfig::episode)
      .def("validate", [](const GripperSimConfig& c) { validate(c); });

  py::class_<GripperSim>(
      m, "GripperSim",
      "A Bullet simulation of a parallel gripper whose two DIGIT gels hold an object. World: z "
      "up, floor at z = 0; fingers along y, the left at +y (REP-103). Deterministic.")
      .def(py::init([](GripperSimConfig config, const SensorModel* sensor) {
             if (sensor) setGelFromSensor(*sensor, config);
             py::gil_scoped_release release;
             return std::make_unique<GripperSim>(config);
           }),
           py::arg("scene"), py::arg("sensor") = nullptr,
           "From a SceneConfig; with a SensorModel the gel pads are the sensor's.")
      .def(
          "reset",
          [](GripperSim& s, std::uint64_t seed, const py::object& height_offset_m) {
            const std::optional<double> offset = offsetFrom(height_offset_m);
            py::gil_scoped_release release;
            const EpisodeStart start = s.reset(seed, offset);
            py::gil_scoped_acquire acquire;
            return episodeDict(start);
          },
          py::arg("seed"), py::arg("height_offset_m") = py::none(),
          "Starts an episode: seats the object at height_offset_m (m above the gel centres; None: "
          "drawn with seed), grasps it and lets it settle. Returns a dict (episode, seed, "
          "height_offset_m, grasp_opening).")
      .def("set_opening", &GripperSim::setOpening, py::arg("opening"),
           "Normalised opening command: 0 closed (min_gap) ... 1 open (max_gap).")
      .def("add_opening", &GripperSim::addOpening, py::arg("delta"),
           "Adds delta to the command, clamped to [0, 1].")
      .def_property_readonly("commanded_opening", &GripperSim::commandedOpening)
      .def_property_readonly("opening", &GripperSim::opening,
                             "where the fingers are, normalised (may lag the command)")
      .def("gap_for_opening", &GripperSim::gapForOpening, py::arg("opening"), "metres")
      .def("step", &GripperSim::step, py::arg("ticks") = 1, Release(),
           "Advances `ticks` physics ticks of tick_seconds each.")
      .def_property_readonly("tick_seconds", &GripperSim::tickSeconds)
      .def_property_readonly("ticks", &GripperSim::ticks)
      .def(
          "contact",
          [](const GripperSim& s, const std::string& finger) {
            return contactDict(s.contact(fingerFrom(finger)));
          },
          py::arg("finger"),
          "What the gel of 'left' or 'right' feels: in_contact, normal_force_n (N), "
          "shear_force_n (N, gel frame), pressure_centre_m (gel x, y, m), twist_moment_nm (N m, "
          "about the gel's +z through that centre), penetration_m, too_deep, object_in_gel (4x4).")
      .def("object_in_world", [](const GripperSim& s) { return poseToNumpy(s.objectInWorld()); })
      .def("gel_in_world", [](const GripperSim& s, const std::string& finger) {
             return poseToNumpy(s.gelInWorld(fingerFrom(finger)));
           }, py::arg("finger"))
      .def_property_readonly("finger_position_m", &GripperSim::fingerPosition)
      .def_property_readonly("config", [](const GripperSim& s) { return s.config(); },
                             "the scene as run (with a hand, its gripper section measured)")
      .def("grip_in_world", [](const GripperSim& s) { return poseToNumpy(s.gripInWorld()); },
           "4x4: origin between the open gels, y from the right gel to the left, z up")
      .def_property_readonly("dropped", &GripperSim::dropped,
                             "the object left both gels and fell below them (this episode)")
      .def_property_readonly("height_offset_range", &GripperSim::heightOffsetRange,
                             "(low, high) m: the offsets reset() accepts")
      .def_property_readonly("collision", [](const GripperSim& s) {
        return py::make_tuple(s.collision().kind, s.collision().parts);
      }, "(kind, convex parts) the object collides as");

  py::class_<TactileGripperOptions> gripper_options(
      m, "TactileGripperOptions",
      "How a TactileGripper runs: contact_sim's and tactile_renderer's parameters, same defaults.");
  bindTactileOptions(gripper_options)
      .def_readwrite("seed", &TactileGripperOptions::seed, "the first episode's seed")
      .def_readwrite("height_offset_m", &TactileGripperOptions::height_offset_m,
                     "the first episode's offset (NaN: drawn)");

  py::class_<TactileGripperBatch>(
      m, "TactileGripperBatch",
      "N simulated grippers with both DIGITs, stepped a sensor frame at a time on a fixed set of "
      "C++ threads (physics, then all sensors' renders). One gripper = a batch of one. Each "
      "gripper gives bit for bit what it gives alone, and what contact_sim and two "
      "tactile_renderers give for the same parameters.")
      .def(py::init([](const GripperSimConfig& scene, const SensorModel& sensor,
                       const std::vector<TactileGripperOptions>& options, int threads) {
             py::gil_scoped_release release;
             return std::make_unique<TactileGripperBatch>(scene, sensor, options, threads);
           }),
           py::arg("scene"), py::arg("sensor"), py::arg("options"), py::arg("threads") = 0,
           "One gripper per TactileGripperOptions; threads 0 = the machine's CPUs.")
      .def_property_readonly("size", &TactileGripperBatch::size)
      .def_property_readonly("threads", &TactileGripperBatch::threads)
      .def(
          "step",
          [](TactileGripperBatch& b, const std::vector<int>& modes, const std::vector<double>& values,
             int frames) {
            std::vector<OpeningCommand> m(modes.size());
            for (std::size_t i = 0; i < modes.size(); ++i) m[i] = openingCommand(modes[i]);
            py::gil_scoped_release release;
            b.step(m, values, frames);
          },
          py::arg("modes"), py::arg("values"), py::arg("frames") = 1,
          "Per gripper: mode 0 (ABSOLUTE) sets the opening to value, 1 (DELTA) adds value "
          "(clamped), 2 (KEEP) keeps the command (norm2tex.envs.commands); then every gripper advances `frames` sensor frames and both sensors render. "
          "An invalid command raises and moves nothing.")
      .def(
          "step_one",
          [](TactileGripperBatch& b, int i, int mode, double value, int frames) {
            TactileGripper& g = b.gripper(i);
            const OpeningCommand command = openingCommand(mode);
            py::gil_scoped_release release;
            if (command == OpeningCommand::kAbsolute) g.sim().setOpening(value);
            if (command == OpeningCommand::kDelta) g.sim().addOpening(value);
            g.step(frames);
          },
          py::arg("index"), py::arg("mode"), py::arg("value"), py::arg("frames") = 1,
          "Steps gripper `index` alone (on this thread): its command (mode as in step()), "
          "`frames` frames, both sensors rendered. The others stand still.")
      .def(
          "reset",
          [](TactileGripperBatch& b, int i, std::uint64_t seed, const py::object& height_offset_m,
             int variant) {
            const std::optional<double> offset = offsetFrom(height_offset_m);
            py::gil_scoped_release release;
            const EpisodeStart start = b.reset(i, seed, offset, variant);
            py::gil_scoped_acquire acquire;
            return episodeDict(start);
          },
          py::arg("index"), py::arg("seed"), py::arg("height_offset_m") = py::none(),
          py::arg("variant") = -1,
          "Starts an episode of gripper `index` (texture variant first; < 0 keeps it) and renders "
          "its first frame. Returns a dict (episode, seed, height_offset_m, grasp_opening).")
      .def("prefetch_variant",
           [](TactileGripperBatch& b, int variant, int i) { b.gripper(i).prefetchVariant(variant); },
           py::arg("variant"), py::arg("index") = 0,
           "Generates a texture variant of gripper `index`'s material in the background, for "
           "every gripper of the batch with that material.")
      .def("images", [](const TactileGripperBatch& b, const std::string& finger) {
             return stackImages(b, fingerFrom(finger));
           }, py::arg("finger"), "(N, rows, cols, 3) uint8 bgr8 frames of one sensor")
      .def("depths", [](const TactileGripperBatch& b, const std::string& finger) {
             const Finger f = fingerFrom(finger);
             py::list out;
             for (int i = 0; i < b.size(); ++i) out.append(toNumpy(b.gripper(i).frame(f).depthMetres()));
             return py::module::import("numpy").attr("stack")(out);
           }, py::arg("finger"), "(N, rows, cols) float32 gel deformation, metres")
      .def("contact_masks", [](const TactileGripperBatch& b, const std::string& finger) {
             const Finger f = fingerFrom(finger);
             py::list out;
             for (int i = 0; i < b.size(); ++i) out.append(toNumpy(b.gripper(i).frame(f).contact_mask));
             return py::module::import("numpy").attr("stack")(out);
           }, py::arg("finger"), "(N, rows, cols) uint8, 255 in contact")
      .def("markers", [](const TactileGripperBatch& b, const std::string& finger) {
             const Finger f = fingerFrom(finger);
             const auto& first = b.gripper(0).frame(f).shear;
             const Py_ssize_t n = b.size();
             const Py_ssize_t count = first ? static_cast<Py_ssize_t>(first->markers.size()) : 0;
             py::array_t<float> current({n, count, Py_ssize_t{2}}), moved({n, count, Py_ssize_t{2}});
             py::array_t<double> slip(n);
             for (int i = 0; i < b.size(); ++i) {
               const auto& shear = b.gripper(i).frame(f).shear;
               slip.mutable_at(i) = shear ? shear->slipFraction() : 0.0;
               for (Py_ssize_t k = 0; k < count; ++k) {
                 const Marker& m = shear->markers[k];
                 current.mutable_at(i, k, 0) = m.current_px.x;
                 current.mutable_at(i, k, 1) = m.current_px.y;
                 moved.mutable_at(i, k, 0) = m.displacement_mm.x;
                 moved.mutable_at(i, k, 1) = m.displacement_mm.y;
               }
             }
             py::dict out;
             out["current_px"] = current;
             out["displacement_mm"] = moved;
             out["slip_fraction"] = slip;
             return out;
           }, py::arg("finger"),
           "One sensor's markers in every gripper: current_px (N, markers, 2) float32 (x = "
           "column, y = row), displacement_mm (N, markers, 2) float32 (gel frame), and "
           "slip_fraction (N,) of each contact (0 without shear). markers is 0 wide when the "
           "sensor has none.")
      .def("background", [](const TactileGripperBatch& b, const std::string& finger) {
             return toNumpy(b.gripper(0).background(fingerFrom(finger)));
           }, py::arg("finger"), "the no-contact frame without noise, (rows, cols, 3) uint8")
      .def(
          "state",
          [](const TactileGripperBatch& b) {
            const Py_ssize_t n = b.size();
            py::array_t<double> opening(n), commanded(n), force({n, Py_ssize_t{2}}),
                penetration({n, Py_ssize_t{2}});
            py::array_t<bool> dropped(n), in_contact({n, Py_ssize_t{2}}), too_deep({n, Py_ssize_t{2}});
            py::array_t<std::int64_t> frame(n);
            for (int i = 0; i < b.size(); ++i) {
              const TactileGripper& g = b.gripper(i);
              opening.mutable_at(i) = g.sim().opening();
              commanded.mutable_at(i) = g.sim().commandedOpening();
              dropped.mutable_at(i) = g.sim().dropped();
              frame.mutable_at(i) = g.frameIndex();
              for (int k = 0; k < 2; ++k) {
                const GelContactState& c = g.sim().contact(static_cast<Finger>(k));
                force.mutable_at(i, k) = c.normal_force_n;
                penetration.mutable_at(i, k) = c.penetration_m;
                in_contact.mutable_at(i, k) = c.in_contact;
                too_deep.mutable_at(i, k) = c.too_deep;
              }
            }
            py::dict out;
            out["opening"] = opening;
            out["commanded_opening"] = commanded;
            out["normal_force_n"] = force;
            out["penetration_m"] = penetration;
            out["in_contact"] = in_contact;
            out["too_deep"] = too_deep;
            out["dropped"] = dropped;
            out["frame"] = frame;
            return out;
          },
          "Per gripper (arrays of N; per sensor (N, 2), left first): opening, commanded_opening, "
          "normal_force_n, penetration_m, in_contact, too_deep, dropped, frame.")
      .def("sim", [](TactileGripperBatch& b, int i) -> GripperSim& { return b.gripper(i).sim(); },
           py::arg("index"), py::return_value_policy::reference_internal,
           "Gripper `index`'s GripperSim (valid while the batch lives).")
      .def("set_noise_seed", [](TactileGripperBatch& b, int i, std::int64_t seed) {
             b.gripper(i).setNoiseSeed(seed);
           }, py::arg("index"), py::arg("noise_seed"), "from gripper index's next frame on (< 0: none)")
      .def("object_in_gel", [](const TactileGripperBatch& b, int i, const std::string& finger) {
             return poseToNumpy(b.gripper(i).objectInGel(fingerFrom(finger)));
           }, py::arg("index"), py::arg("finger"),
           "The pose gripper index's sensor renders the object at (4x4, object in gel frame, m)")
      .def("variant", [](const TactileGripperBatch& b, int i) { return b.gripper(i).variant(); })
      .def("beta_mm", [](const TactileGripperBatch& b, int i) { return b.gripper(i).betaMm(); })
      .def("friction", [](const TactileGripperBatch& b, int i) { return b.gripper(i).friction(); })
      .def_property_readonly("frame_seconds",
                             [](const TactileGripperBatch& b) { return b.gripper(0).frameSeconds(); });
}

}  // namespace python
}  // namespace norm2tex
