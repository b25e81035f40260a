// Basic types shared by the engine. All quantities are SI (m, kg, s, N, Pa, rad).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>

namespace rocklab {

using Vec3 = Eigen::Vector3d;

/// Degrees of freedom of a rigid body, used as bit positions in a fixity mask.
enum Dof : std::uint8_t { kX = 0, kY = 1, kZ = 2, kRx = 3, kRy = 4, kRz = 5 };

inline constexpr std::uint8_t dof_bit(int dof) {
  return static_cast<std::uint8_t>(1u << dof);
}

/// Rotate vector v by the rotation vector phi (axis * angle) with Rodrigues' formula.
inline Vec3 rotate_by(const Vec3& v, const Vec3& phi) {
  const double angle = phi.norm();
  if (angle < 1e-300)
    return v;
  return Eigen::AngleAxisd(angle, phi / angle) * v;
}

/// Orientation q turned further by the rotation vector phi (axis * angle, global frame).
inline Eigen::Quaterniond turn_by(const Eigen::Quaterniond& q, const Vec3& phi) {
  const double angle = phi.norm();
  if (angle < 1e-300)
    return q;
  return (Eigen::Quaterniond(Eigen::AngleAxisd(angle, phi / angle)) * q).normalized();
}

/// The rotation vector (axis * angle, angle in [0, pi]) of the orientation q; in 2D its z
/// component is the signed angle turned about z.
inline Vec3 rotation_vector(const Eigen::Quaterniond& q) {
  const Eigen::AngleAxisd aa(q);
  return aa.angle() * aa.axis();
}

} // namespace rocklab
