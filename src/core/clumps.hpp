// Clumps: rigid bodies made of overlapping or touching pebbles (balls that move with the body and
// have no contacts among themselves). Units SI (m, kg, s, N, rad).
//
// Mass properties come from the union of the pebbles (overlaps counted once): exactly by sums
// and the parallel-axis theorem when no two pebbles overlap, otherwise by midpoint integration
// on a regular grid over the bounding box (kUnionGrid cells per side). The body frame is the
// principal frame of the inertia tensor about the centroid (2D: the global axes; only I_zz
// matters for unit-thickness disks rotating in the xy plane).
//
// Motion: leapfrog for the centroid (as for balls) and, for rotation, the global angular
// momentum L is kicked by the torque and the orientation quaternion is advanced by the
// symmetric splitting of the free rigid body into exact rotations about the principal axes
// (x/2, y/2, z, y/2, x/2). Each sub-flow conserves L exactly, so a torque-free clump keeps its
// angular momentum to round-off and its energy to O((w dt)^2) without drift.
#pragma once

#include "core/types.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace rocklab {

/// Cells per side of the union-integration grid (3D: n^3 cells, 2D: n^2).
inline constexpr int kUnionGrid3D = 96;
inline constexpr int kUnionGrid2D = 512;

struct Pebble {
  Vec3 position = Vec3::Zero(); ///< [m]
  double radius = 0;            ///< [m]
};

struct MassProperties {
  double mass = 0;                                   ///< [kg] (2D: per unit thickness)
  Vec3 centroid = Vec3::Zero();                      ///< [m]
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero(); ///< about the centroid, global axes [kg m^2]
  bool exact = true; ///< false: the pebbles overlap and the grid integration was used
};

/// Mass, centroid and inertia tensor of the union of the pebbles at uniform density [kg/m^3].
MassProperties union_mass_properties(const std::vector<Pebble>& pebbles, double density, int dim);

/// Pebbles of a named template, unit radius, centroid of the pebble centres at the origin.
/// Names: "single", "pair" (two touching), "line3" (three touching in a row), "triangle3"
/// (three mutually touching, the thesis' three-pebble rock), "tetra4" (3D: four mutually
/// touching). Throws std::invalid_argument for an unknown name.
std::vector<Pebble> clump_template(const std::string& name, int dim);

struct Clump {
  std::int64_t id = 0;
  std::int32_t group = 0;            ///< group index of the clump and all its pebbles
  std::vector<std::int32_t> pebbles; ///< ball indices
  std::vector<Vec3> offset;          ///< pebble centres in the body frame [m]
  double mass = 0;                   ///< [kg]
  Vec3 inertia = Vec3::Ones();       ///< principal moments (body axes) [kg m^2]
  Vec3 pos = Vec3::Zero();           ///< centroid [m]
  Vec3 vel = Vec3::Zero();           ///< centroid velocity (half step) [m/s]
  Vec3 L = Vec3::Zero();             ///< angular momentum about the centroid, global (half step)
  Vec3 spin = Vec3::Zero();          ///< angular velocity, global [rad/s]
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity(); ///< body -> global
  Vec3 applied_force = Vec3::Zero();                     ///< [N]
  Vec3 applied_moment = Vec3::Zero();                    ///< [N m]
  // accumulated energy [J] (group energy tracing)
  double body_work = 0, gravity_work = 0, local_damping = 0;

  /// Angular velocity from L and the orientation: w = q I^-1 q^-1 L.
  Vec3 angular_velocity() const;
  double kinetic_translational() const { return 0.5 * mass * vel.squaredNorm(); }
  double kinetic_rotational() const;
};

/// Advance the orientation by the free rotation of a body with principal moments I over h
/// (the splitting above); Lb is the body-frame angular momentum, updated in place.
void free_rotation(Eigen::Quaterniond& q, Vec3& Lb, const Vec3& I, double h, int dim);

} // namespace rocklab
