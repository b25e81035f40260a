// Balls (2D unit-thickness disks or 3D spheres) stored as structure-of-arrays.
#pragma once

#include "core/types.hpp"

#include <numbers>
#include <string>
#include <vector>

namespace rocklab {

/// All balls of a model. Index i addresses the same ball in every array.
struct Balls {
  std::vector<Vec3> pos;            ///< centre position [m]
  std::vector<Vec3> vel;            ///< translational velocity [m/s] (at the half step)
  std::vector<Vec3> spin;           ///< rotational velocity [rad/s] (at the half step)
  std::vector<Vec3> force;          ///< resultant contact force of the current step [N]
  std::vector<Vec3> moment;         ///< resultant contact moment of the current step [N m]
  std::vector<Vec3> applied_force;  ///< user-applied external force [N]
  std::vector<Vec3> applied_moment; ///< user-applied external moment [N m]
  std::vector<Vec3> disp;           ///< displacement since the last contact detection [m]
  std::vector<double> radius;       ///< radius [m]
  std::vector<double> mass;         ///< mass [kg]
  std::vector<double> inertia;      ///< moment of inertia about any centroidal axis [kg m^2]
  std::vector<double> density;      ///< density [kg/m^3]
  std::vector<std::uint8_t> fixity; ///< bit set of fixed DOFs (see Dof): velocity held constant
  std::vector<std::int32_t> group;  ///< index into the model's group-name table
  std::vector<std::int64_t> id;     ///< user id, unique
  std::vector<std::int32_t> clump;  ///< clump index of a pebble, -1 for a free ball
  // Accumulated energy of the ball's own motion [J], for group energy tracing (Eq. 2-3). A
  // pebble's work is its clump's.
  std::vector<double> body_work;    ///< gravity and applied loads
  std::vector<double> gravity_work; ///< the gravity part
  std::vector<double> damping_work; ///< dissipated by local damping
  /// Orientation of each ball's body frame relative to the global frame, integrated from the spin
  /// (a pebble takes its clump's). Empty unless tracking is on (track_orientation): like PFC's
  /// orientation tracking it is opt-in, as nothing in the mechanics depends on it.
  std::vector<Eigen::Quaterniond> orient;

  std::size_t size() const { return pos.size(); }
  /// Call f(v) on every per-ball array (orient only while tracked): the one list that edits
  /// moving or removing balls go through.
  template <class F> void for_each_array(F&& f) {
    f(pos), f(vel), f(spin), f(force), f(moment), f(applied_force), f(applied_moment), f(disp);
    f(radius), f(mass), f(inertia), f(density), f(fixity), f(group), f(id), f(clump);
    f(body_work), f(gravity_work), f(damping_work);
    if (tracking_)
      f(orient);
  }
  bool tracks_orientation() const { return tracking_; }
  /// Turn tracking on (every ball starts from the identity, i.e. "now" is the reference) or off.
  void track_orientation(bool on) {
    tracking_ = on;
    orient.assign(on ? size() : 0, Eigen::Quaterniond::Identity());
  }

  /// Change a radius, keeping density: mass and inertia follow.
  void set_radius(std::size_t i, double r, int dim) {
    const double pi = std::numbers::pi;
    radius[i] = r;
    mass[i] = dim == 2 ? density[i] * pi * r * r : density[i] * 4.0 / 3.0 * pi * r * r * r;
    inertia[i] = (dim == 2 ? 0.5 : 0.4) * mass[i] * r * r;
  }

  /// Append a ball; mass and inertia follow from density (2D: unit-thickness disk).
  std::size_t add(int dim, std::int64_t user_id, const Vec3& x, double r, double rho,
                  std::int32_t group_index) {
    const double pi = std::numbers::pi;
    double m = 0, inert = 0;
    if (dim == 2) {
      m = rho * pi * r * r; // unit thickness
      inert = 0.5 * m * r * r;
    } else {
      m = rho * 4.0 / 3.0 * pi * r * r * r;
      inert = 0.4 * m * r * r;
    }
    pos.push_back(x);
    vel.push_back(Vec3::Zero());
    spin.push_back(Vec3::Zero());
    force.push_back(Vec3::Zero());
    moment.push_back(Vec3::Zero());
    applied_force.push_back(Vec3::Zero());
    applied_moment.push_back(Vec3::Zero());
    disp.push_back(Vec3::Zero());
    radius.push_back(r);
    mass.push_back(m);
    inertia.push_back(inert);
    density.push_back(rho);
    fixity.push_back(0);
    group.push_back(group_index);
    id.push_back(user_id);
    clump.push_back(-1);
    body_work.push_back(0);
    gravity_work.push_back(0);
    damping_work.push_back(0);
    if (tracking_)
      orient.push_back(Eigen::Quaterniond::Identity());
    return pos.size() - 1;
  }

private:
  bool tracking_ = false;
};

} // namespace rocklab
