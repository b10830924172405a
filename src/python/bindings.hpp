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

}  // namespace python
}  // namespace norm2tex
