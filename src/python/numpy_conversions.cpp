#include "numpy_conversions.hpp"

#include <pybind11/eigen.h>

#include <cmath>
#include <cstring>
#include <vector>

namespace norm2tex {
namespace python {
namespace {

py::dtype dtypeOf(int depth) {
  switch (depth) {
    case CV_8U:
      return py::dtype::of<std::uint8_t>();
    case CV_16S:
      return py::dtype::of<std::int16_t>();
    case CV_32S:
      return py::dtype::of<std::int32_t>();
    case CV_32F:
      return py::dtype::of<float>();
    case CV_64F:
      return py::dtype::of<double>();
    default:
      throw std::invalid_argument("no numpy type for OpenCV depth " + std::to_string(depth));
  }
}

}  // namespace

py::array toNumpy(const cv::Mat& mat) {
  std::vector<Py_ssize_t> shape = {mat.rows, mat.cols};
  if (mat.channels() > 1) shape.push_back(mat.channels());
  py::array out(dtypeOf(mat.depth()), shape);
  const std::size_t row_bytes = mat.cols * mat.elemSize();
  auto* dst = static_cast<unsigned char*>(out.mutable_data());
  for (int r = 0; r < mat.rows; ++r) std::memcpy(dst + r * row_bytes, mat.ptr(r), row_bytes);
  return out;
}

cv::Mat fromNumpy(const py::handle& handle, int type, const std::string& what) {
  const int depth = CV_MAT_DEPTH(type);
  const int channels = CV_MAT_CN(type);
  py::array array = py::array::ensure(handle);
  if (!array) throw py::value_error(what + ": not an array");
  if (!array.dtype().is(dtypeOf(depth))) {
    throw py::value_error(what + ": dtype " + std::string(py::str(array.dtype())) + ", expected " +
                          std::string(py::str(dtypeOf(depth))));
  }
  const bool shape_ok =
      channels == 1 ? array.ndim() == 2 : array.ndim() == 3 && array.shape(2) == channels;
  if (!shape_ok) {
    throw py::value_error(
        what + ": shape must be (rows, cols" +
        (channels == 1 ? std::string(")") : ", " + std::to_string(channels) + ")"));
  }
  // C order, so that rows are contiguous (a copy only when the array is not).
  py::array c = py::array::ensure(array, py::array::c_style);
  cv::Mat out(static_cast<int>(c.shape(0)), static_cast<int>(c.shape(1)), type);
  std::memcpy(out.data, c.data(), out.total() * out.elemSize());
  return out;
}

Eigen::Isometry3d poseFromPython(const py::handle& pose, const std::string& what) {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  if (py::isinstance<py::tuple>(pose) || py::isinstance<py::list>(pose)) {
    py::sequence parts = py::reinterpret_borrow<py::sequence>(pose);
    if (parts.size() != 2) {
      throw py::value_error(what + ": expected a 4x4 matrix or (xyz, quaternion xyzw)");
    }
    auto xyz = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(parts[0]);
    auto q = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(parts[1]);
    if (!xyz || !q || xyz.size() != 3 || q.size() != 4) {
      throw py::value_error(what + ": (xyz, quaternion xyzw) needs 3 and 4 numbers");
    }
    const Eigen::Quaterniond quat(q.at(3), q.at(0), q.at(1), q.at(2));
    const Eigen::Vector3d t(xyz.at(0), xyz.at(1), xyz.at(2));
    // A non-finite pose goes through: the C++ call refuses it with its own message.
    if (quat.coeffs().allFinite() && std::abs(quat.norm() - 1.0) > 1e-6) {
      throw py::value_error(what + ": the quaternion's norm is " + std::to_string(quat.norm()) +
                            ", not 1");
    }
    out.linear() = quat.coeffs().allFinite() ? quat.normalized().toRotationMatrix()
                                             : Eigen::Matrix3d::Constant(std::nan(""));
    out.translation() = t;
    return out;
  }
  auto m = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(pose);
  if (!m || m.ndim() != 2 || m.shape(0) != 4 || m.shape(1) != 4) {
    throw py::value_error(what + ": expected a 4x4 matrix or (xyz, quaternion xyzw)");
  }
  Eigen::Matrix4d matrix;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) matrix(r, c) = m.at(r, c);
  const Eigen::Matrix3d rotation = matrix.topLeftCorner<3, 3>();
  const bool rigid = (rotation.transpose() * rotation).isIdentity(1e-6) &&
                     rotation.determinant() > 0.0 &&
                     matrix.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1));
  if (matrix.allFinite() && !rigid) {
    throw py::value_error(what +
                          ": not a rigid transform (rotation not orthonormal, or last row "
                          "not 0 0 0 1)");
  }
  out.matrix() = matrix;
  return out;
}

py::array_t<double> poseToNumpy(const Eigen::Isometry3d& pose) {
  py::array_t<double> out({4, 4});
  auto m = out.mutable_unchecked<2>();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = pose.matrix()(r, c);
  return out;
}

py::dict contactDict(const GelContactState& c) {
  py::dict out;
  out["in_contact"] = c.in_contact;
  out["normal_force_n"] = c.normal_force_n;
  out["shear_force_n"] = Eigen::Vector3d(c.shear_force_n);
  out["pressure_centre_m"] = Eigen::Vector2d(c.pressure_centre_m);
  out["twist_moment_nm"] = c.twist_moment_nm;
  out["penetration_m"] = c.penetration_m;
  out["too_deep"] = c.too_deep;
  out["object_in_gel"] = poseToNumpy(c.object_in_gel);
  return out;
}

}  // namespace python
}  // namespace norm2tex
