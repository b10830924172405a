#pragma once

// numpy <-> OpenCV / Eigen for the bindings: shapes and dtypes checked, one copy each way.
//
// Why copies: the renderer and the simulation reuse their frame buffers at the next call, so a
// view handed to Python would change under the user; images are 230 kB, one copy costs ~20 us.

#include <string>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "norm2tex/sim/gripper_sim.hpp"

namespace norm2tex {
namespace python {

namespace py = pybind11;

/// A new numpy array with the matrix's rows x cols (x channels when > 1), of its element type.
py::array toNumpy(const cv::Mat& mat);

/// A new cv::Mat of `type` from a C-contiguous (or castable) numpy array of shape (rows, cols)
/// or (rows, cols, channels); throws ValueError naming `what` for another shape or dtype.
cv::Mat fromNumpy(const py::handle& array, int type, const std::string& what);

/// A pose from Python: a 4 x 4 homogeneous matrix, or (xyz, quaternion xyzw) -- metres. Throws
/// ValueError naming `what` for another shape, a non-unit quaternion or a non-rigid rotation.
/// A non-finite pose is passed on, for the C++ call to refuse with its own message.
Eigen::Isometry3d poseFromPython(const py::handle& pose, const std::string& what);

/// A pose as a 4 x 4 float64 numpy array.
py::array_t<double> poseToNumpy(const Eigen::Isometry3d& pose);

/// What one gel feels, as the simulations' contact() returns it in Python: a dict of
/// in_contact, normal_force_n, shear_force_n (gel frame), penetration_m, too_deep,
/// object_in_gel (4x4).
py::dict contactDict(const GelContactState& contact);

}  // namespace python
}  // namespace norm2tex
