// norm2tex._core: the package's C++ core from Python. Thin bindings, no logic of their own:
// types are translated (numpy arrays, poses, dicts), errors become norm2tex.Error with the
// C++ message, and the GIL is released while C++ renders, steps or bakes.

#include <pybind11/pybind11.h>

#include "bindings.hpp"
#include "norm2tex/common/error.hpp"

namespace py = pybind11;

PYBIND11_MODULE(_core, m) {
  m.doc() =
      "norm2tex's C++ core: DIGIT sensor models, object meshes, height atlases (H_global), "
      "materials, the tactile renderer and the gripper simulation. Units: metres for poses and "
      "positions, millimetres where a name ends in _mm, newtons for forces. Poses are 4x4 "
      "homogeneous matrices (numpy float64) or (xyz, quaternion xyzw) pairs; poses returned "
      "are 4x4 matrices. Images are numpy arrays: bgr8 (rows, cols, 3) uint8 as the DIGIT "
      "publishes them, depth (rows, cols) float32 in metres, masks (rows, cols) uint8.";
  // RuntimeError's subclass: the one error type of the core, message unchanged.
  py::register_exception<norm2tex::Error>(m, "Error", PyExc_RuntimeError);
  norm2tex::python::bindRender(m);
  norm2tex::python::bindSim(m);
  norm2tex::python::bindHand(m);
  m.attr("SOURCE_CONFIG_DIR") = NORM2TEX_SOURCE_CONFIG_DIR;
  m.attr("__version__") = NORM2TEX_VERSION;
}
