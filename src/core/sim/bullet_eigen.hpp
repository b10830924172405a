#pragma once
// Private to norm2tex_sim: Eigen <-> Bullet conversions.

#include <LinearMath/btTransform.h>

#include <Eigen/Geometry>

namespace norm2tex {

inline btVector3 toBt(const Eigen::Vector3d& v) { return btVector3(v.x(), v.y(), v.z()); }
inline Eigen::Vector3d toEigen(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

inline btTransform toBt(const Eigen::Isometry3d& pose) {
  const Eigen::Quaterniond q(pose.rotation());
  return btTransform(btQuaternion(q.x(), q.y(), q.z(), q.w()), toBt(pose.translation()));
}

inline Eigen::Isometry3d toEigen(const btTransform& t) {
  const btQuaternion q = t.getRotation();
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::Quaterniond(q.w(), q.x(), q.y(), q.z()).normalized().toRotationMatrix();
  pose.translation() = toEigen(t.getOrigin());
  return pose;
}

}  // namespace norm2tex
