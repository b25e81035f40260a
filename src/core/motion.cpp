// The law of motion: central differences with local damping for balls, and the rigid-body update
// of clumps (free-rotation splitting), with the work of body forces and damping booked per body.
#include "core/model.hpp"

#include "core/parallel.hpp"
#include <algorithm>
#include <cmath>
#include <omp.h>
#include <sstream>

namespace rocklab {

using namespace detail;

void Model::move_clumps(double dt, std::array<double, 4>& sums) {
  if (clumps.empty())
    return;
  const int dim = settings.dim;
  const double alpha = settings.local_damping;
  const Vec3 gvec = settings.gravity;
  const int ntran = dim == 2 ? 2 : 3;
  const bool track = balls.tracks_orientation();
  const auto s = block_sum<4>(clumps.size(), [&](std::size_t k, std::array<double, 4>& acc) {
    Clump& c = clumps[k];
    // Resultant about the centroid: pebble contact forces and moments, gravity on the union's
    // mass, applied loads.
    Vec3 F = Vec3::Zero(), M = Vec3::Zero();
    for (std::int32_t p : c.pebbles) {
      const std::size_t i = static_cast<std::size_t>(p);
      F += balls.force[i];
      M += balls.moment[i] + (balls.pos[i] - c.pos).cross(balls.force[i]);
    }
    const Vec3 Fg = c.mass * gvec;
    const Vec3 Fbody = Fg + c.applied_force;
    F += Fbody;
    M += c.applied_moment;
    double bw = 0, gw = 0, dw = 0;
    for (int d = 0; d < ntran; ++d) {
      const double v0 = c.vel[d];
      const double Fd = -alpha * std::abs(F[d]) * sign(v0);
      const double v1 = v0 + (F[d] + Fd) / c.mass * dt;
      c.vel[d] = v1;
      dw -= Fd * 0.5 * (v0 + v1) * dt;
      bw += Fbody[d] * 0.5 * (v0 + v1) * dt; // Eq. 2
      gw += Fg[d] * 0.5 * (v0 + v1) * dt;    // Eq. 3
    }
    const Vec3 w0 = c.spin;
    Vec3 Md = Vec3::Zero();
    for (int d = (dim == 2 ? 2 : 0); d < 3; ++d)
      Md[d] = -alpha * std::abs(M[d]) * sign(w0[d]);
    c.L += (M + Md) * dt;
    if (dim == 2)
      c.L.x() = c.L.y() = 0;
    Vec3 Lb = c.q.conjugate() * c.L;
    const Eigen::Quaterniond q0 = c.q;
    free_rotation(c.q, Lb, c.inertia, dt, dim);
    // This step's rotation in the global frame, for the pebbles' orientations (tracking only).
    const Eigen::Quaterniond turn = track ? c.q * q0.conjugate() : Eigen::Quaterniond::Identity();
    c.spin = c.q * Lb.cwiseQuotient(c.inertia);
    const Vec3 wm = 0.5 * (w0 + c.spin);
    dw -= Md.dot(wm) * dt;
    bw += c.applied_moment.dot(wm) * dt;
    c.pos += c.vel * dt;
    for (std::size_t a = 0; a < c.pebbles.size(); ++a) {
      const std::size_t i = static_cast<std::size_t>(c.pebbles[a]);
      const Vec3 arm = c.q * c.offset[a];
      const Vec3 x = c.pos + arm;
      balls.disp[i] += x - balls.pos[i];
      balls.pos[i] = x;
      balls.vel[i] = c.vel + c.spin.cross(arm);
      balls.spin[i] = c.spin;
      if (track)
        balls.orient[i] = (turn * balls.orient[i]).normalized();
    }
    c.body_work += bw;
    c.gravity_work += gw;
    c.local_damping += dw;
    acc[0] += bw;
    acc[1] += gw;
    acc[3] += dw;
  });
  for (int k = 0; k < 4; ++k)
    sums[static_cast<std::size_t>(k)] += s[static_cast<std::size_t>(k)];
}

void Model::law_of_motion(double dt) {
  const int dim = settings.dim;
  const double alpha = settings.local_damping;
  const Vec3 gvec = settings.gravity;
  const int ntran = dim == 2 ? 2 : 3;
  const bool track = balls.tracks_orientation();
  // acc: 0 body work, 1 gravity work, 2 boundary (constraint) work, 3 local damping, 4 max |v|
  // and 5 max displacement are handled with separate reductions below.
  // What a ball's step adds to the ledger, in the order block_sum's accumulator took it: the
  // constraint work of each fixed DOF (translations, then rotations; +0 for a free one leaves the
  // sum unchanged), then the body, gravity and damping work.
  auto add = [](std::array<double, 4>& acc, const BallWork& r) {
    for (double c : r.constraint)
      acc[2] -= c;
    acc[0] += r.body;
    acc[1] += r.gravity;
    acc[3] += r.damping;
  };
  auto sums = plan_block_sum<4>(
      plan_threads(), motion_spill_, motion_parts_,
      [&](std::size_t i) {
        BallWork r;
        if (balls.clump[i] >= 0)
          return r; // pebbles move with their clump (move_clumps)
        const double m = inertial_mass(i);
        double bw = 0, gw = 0, dw = 0; // this ball's body, gravity and damping work
        const std::uint8_t fix = balls.fixity[i];
        const Vec3 Fg = balls.mass[i] * gvec; // gravity acts on the true mass
        const Vec3 Fbody = Fg + balls.applied_force[i];
        const Vec3 F = balls.force[i] + Fbody;
        Vec3& v = balls.vel[i];
        for (int d = 0; d < ntran; ++d) {
          const double v0 = v[d];
          double v1 = v0;
          if (fix & dof_bit(d)) {
            r.constraint[static_cast<std::size_t>(d)] = F[d] * v0 * dt; // -F holds the velocity
          } else {
            const double Fd = -alpha * std::abs(F[d]) * sign(v0);
            v1 = v0 + (F[d] + Fd) / m * dt;
            dw -= Fd * 0.5 * (v0 + v1) * dt;
          }
          v[d] = v1;
          bw += Fbody[d] * 0.5 * (v0 + v1) * dt; // Eq. 2
          gw += Fg[d] * 0.5 * (v0 + v1) * dt;    // Eq. 3
        }
        const double I = inertial_inertia(i);
        const Vec3 M = balls.moment[i] + balls.applied_moment[i];
        Vec3& w = balls.spin[i];
        for (int d = (dim == 2 ? 2 : 0); d < 3; ++d) {
          const double w0 = w[d];
          double w1 = w0;
          if (fix & dof_bit(3 + d)) {
            r.constraint[static_cast<std::size_t>(3 + d)] = M[d] * w0 * dt;
          } else {
            const double Md = -alpha * std::abs(M[d]) * sign(w0);
            w1 = w0 + (M[d] + Md) / I * dt;
            dw -= Md * 0.5 * (w0 + w1) * dt;
          }
          w[d] = w1;
          bw += balls.applied_moment[i][d] * 0.5 * (w0 + w1) * dt;
        }
        if (track) // turned by the mid-step spin, as the position is moved by the mid-step velocity
          balls.orient[i] = turn_by(balls.orient[i], w * dt);
        const Vec3 dx = v * dt;
        balls.pos[i] += dx;
        balls.disp[i] += dx;
        balls.body_work[i] += bw;
        balls.gravity_work[i] += gw;
        balls.damping_work[i] += dw;
        r.body = bw, r.gravity = gw, r.damping = dw;
        return r;
      },
      add);
  move_clumps(dt, sums);
  ledger_.body_work += sums[0];
  ledger_.gravity_work += sums[1];
  ledger_.boundary_work += sums[2];
  ledger_.local_damping += sums[3];
  track_motion(dt);
}

void Model::track_motion(double dt) {
  // The largest speed and displacement since detection (time step, detection trigger), and the
  // blow-up checks: a ball moving more than its radius in a step, a non-finite state.
  const std::size_t n = balls.size();
  const ThreadPlan& plan = plan_threads();
  range_parts_.resize(plan.threads);
  for_ranges(plan.ball, [&](std::size_t t, std::size_t begin, std::size_t end) {
    double vmax = 0, dmax = 0, step_ratio = 0;
    bool bad = false;
    for (std::size_t i = begin; i < end; ++i) {
      vmax = std::max(vmax, balls.vel[i].norm() + balls.radius[i] * balls.spin[i].norm());
      // A ball that moves more than its radius or turns more than a radian in one step.
      step_ratio = std::max(
          {step_ratio, balls.vel[i].norm() * dt / balls.radius[i], balls.spin[i].norm() * dt});
      dmax = std::max(dmax, balls.disp[i].norm());
      bad = bad || !balls.pos[i].allFinite() || !balls.vel[i].allFinite() ||
            !balls.spin[i].allFinite();
    }
    range_parts_[t] = {vmax, dmax, step_ratio, bad ? 1.0 : 0.0};
  });
  double vmax = 0, dmax = 0, step_ratio = 0;
  bool bad = false;
  for (std::size_t t = 0; t < plan.threads; ++t) {
    vmax = std::max(vmax, range_parts_[t][0]);
    dmax = std::max(dmax, range_parts_[t][1]);
    step_ratio = std::max(step_ratio, range_parts_[t][2]);
    bad = bad || range_parts_[t][3] != 0;
  }
  max_speed_ = vmax;
  max_ball_disp_ = dmax;
  if (step_ratio > 1) {
    // A ball that moves more than its radius in one step can pass through a contact unseen.
    for (std::size_t i = 0; i < n; ++i)
      if (balls.vel[i].norm() * dt > balls.radius[i]) {
        std::ostringstream msg;
        msg << "physical blow-up at step " << step_ << " (t = " << time_ << " s): ball id "
            << balls.id[i] << " moved " << balls.vel[i].norm() * dt
            << " m in one step, more than its radius " << balls.radius[i]
            << " m; reduce the time step";
        throw PhysicsError(msg.str());
      } else if (balls.spin[i].norm() * dt > 1) {
        std::ostringstream msg;
        msg << "physical blow-up at step " << step_ << " (t = " << time_ << " s): ball id "
            << balls.id[i] << " turned " << balls.spin[i].norm() * dt << " rad in one step (spin "
            << balls.spin[i].norm() << " rad/s), more than 1 rad; reduce the time step or the spin";
        throw PhysicsError(msg.str());
      }
  }
  if (bad) {
    for (std::size_t i = 0; i < n; ++i)
      if (!balls.pos[i].allFinite() || !balls.vel[i].allFinite() || !balls.spin[i].allFinite()) {
        std::ostringstream msg;
        msg << "physical blow-up at step " << step_ << " (t = " << time_ << " s): ball id "
            << balls.id[i] << " has a non-finite position, velocity or spin; reduce the time step";
        throw PhysicsError(msg.str());
      }
  }
}

} // namespace rocklab
