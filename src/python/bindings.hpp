#pragma once

#include <pybind11/pybind11.h>

namespace norm2tex {
namespace python {

/// SensorModel, TexturedMesh and object loading, HeightAtlas and baking, materials,
/// TactileRenderer (bind_render.cpp).
void bindRender(pybind11::module& m);
/// The scene config, GripperSim, TactileGripper and TactileGripperBatch (bind_sim.cpp).
void bindSim(pybind11::module& m);
/// HandConfig, HandSimConfig, HandSim and TactileHand: any hand from its URDF (bind_hand.cpp).
void bindHand(pybind11::module& m);

/// The fields TactileGripperOptions and TactileHandOptions share (rates, material, variant,
/// beta, friction, noise), bound alike on either class.
template <typename Options>
pybind11::class_<Options>& bindTactileOptions(pybind11::class_<Options>& c) {
  return c.def(pybind11::init<>())
      .def_readwrite("frame_rate_hz", &Options::frame_rate_hz)
      .def_readwrite("physics_rate_hz", &Options::physics_rate_hz)
      .def_readwrite("material_config", &Options::material_config,
                     "config/materials/<name>.yaml; '' = no material")
      .def_readwrite("variant", &Options::variant)
      .def_readwrite("material_seed", &Options::material_seed)
      .def_readwrite("beta_mm", &Options::beta_mm, "< 0: the material's; 0: none")
      .def_readwrite("friction", &Options::friction, "< 0: the material's")
      .def_readwrite("noise_seed", &Options::noise_seed, "< 0: no noise")
      .def_readwrite("noise_per_episode", &Options::noise_per_episode,
                     "count the noise's frames from each reset (else from construction, as ROS)")
      .def_readwrite("shear", &Options::shear,
                     "render the gel's lateral motion from the physics' tangential force (always "
                     "on when the sensor has markers)");
}

}  // namespace python
}  // namespace norm2tex
