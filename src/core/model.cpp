// The Model: set-up, the cycle (time step, motion, walls, detection, forces) and measures of
// the state. The stages live in detection.cpp, forces.cpp, motion.cpp, energy.cpp and editing.cpp.
#include "core/model.hpp"

#include "core/parallel.hpp"
#include "core/thread_lease.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <omp.h>

namespace rocklab {

using namespace detail;

int Model::group_index(const std::string& name) {
  for (std::size_t i = 0; i < group_names.size(); ++i)
    if (group_names[i] == name)
      return static_cast<int>(i);
  group_names.push_back(name);
  return static_cast<int>(group_names.size() - 1);
}

void Model::ensure_thread_buffers() {
  // Per-thread buffers are indexed by thread number; the thread count may change between calls.
  const std::size_t nthreads = static_cast<std::size_t>(omp_get_max_threads());
  if (thread_events_.size() < nthreads)
    thread_events_.resize(nthreads);
  if (thread_keys_.size() < nthreads)
    thread_keys_.resize(nthreads);
}

void Model::initialize() {
  ensure_thread_buffers();
  for (auto& w : walls)
    w.update_bounds();
  margin_ = settings.margin;
  if (margin_ <= 0) {
    double sum = 0;
    for (double r : balls.radius)
      sum += r;
    margin_ = balls.size() ? 0.1 * sum / static_cast<double>(balls.size()) : 0.0;
  }
  // The speed cap of the automatic step needs the initial velocities before the first step.
  max_speed_ = fastest_point_speed();
  detect();
  force_displacement(0.0);
  const EnergyLedger e = energy();
  ledger_.initial_total = e.kinetic() + e.stored();
  initialized_ = true;
}

void Model::cycle(std::int64_t count) {
  if (!initialized_)
    initialize();
  follow_thread_lease(); // a parent running several processes may lend or take back cores
  ensure_thread_buffers();
  if (adj_start_.size() != balls.size() + 1) { // balls added since the last detection
    detect();                                  // their contacts, adjacency and thread ranges
    max_speed_ = std::max(max_speed_, fastest_point_speed());
  }
  if (mass_scale_.size() != balls.size() && !mass_scale_.empty()) { // balls added or removed
    mass_scale_.clear();
    inertia_scale_.clear();
  }
  for (std::int64_t k = 0; k < count; ++k) {
    const double dt = estimate_timestep();
    dt_ = dt;
    law_of_motion(dt);
    double wall_work = 0;
    for (Wall& w : walls) {
      // Energy a moving wall puts in: the force on the balls (-force) times the wall motion.
      wall_work -=
          (w.force.dot(w.velocity) + w.moment.dot(w.spin) + w.radial_force * w.radial_velocity) *
          dt;
      wall_disp_ += w.max_vertex_speed() * dt;
      w.move(dt);
    }
    ledger_.boundary_work += wall_work;
    time_ += dt;
    ++step_;
    if (needs_detection())
      detect();
    force_displacement(dt);
  }
}

double Model::fastest_point_speed() const {
  double v = 0;
  for (std::size_t i = 0; i < balls.size(); ++i)
    v = std::max(v, balls.vel[i].norm() + balls.radius[i] * balls.spin[i].norm());
  return v;
}

double Model::estimate_timestep() const {
  if (settings.timestep > 0)
    return settings.timestep;
  double dt = settings.timestep_safety * dt_stiffness_;
  // Nothing may move more than a quarter of the margin in one step, so that contacts exist
  // before the pieces touch.
  if (max_speed_ > 0)
    dt = std::min(dt, 0.25 * margin_ / max_speed_);
  const double g = settings.gravity.norm();
  if (g > 0)
    dt = std::min(dt, std::sqrt(0.25 * margin_ / g));
  for (const Wall& w : walls) {
    const double v = w.max_vertex_speed();
    if (v > 0)
      dt = std::min(dt, 0.25 * margin_ / v);
  }
  if (!std::isfinite(dt) || dt <= 0)
    dt = 1e-3; // nothing constrains the step: no contacts, no motion, no gravity
  return dt;
}

double Model::mean_unbalanced_force_ratio(bool with_moments) const {
  const int ntran = settings.dim == 2 ? 2 : 3;
  const auto ub = block_sum<1>(balls.size(), [&](std::size_t i, std::array<double, 1>& acc) {
    if (balls.clump[i] >= 0)
      return;
    const Vec3 F = balls.force[i] + balls.mass[i] * settings.gravity + balls.applied_force[i];
    double s = 0;
    for (int d = 0; d < ntran; ++d)
      if (!(balls.fixity[i] & dof_bit(d)))
        s += F[d] * F[d];
    if (with_moments) { // the free rotations' unbalanced moment as a force at the radius
      const Vec3 M = (balls.moment[i] + balls.applied_moment[i]) / balls.radius[i];
      for (int d = settings.dim == 2 ? kRz : kRx; d <= kRz; ++d)
        if (!(balls.fixity[i] & dof_bit(d)))
          s += M[d - kRx] * M[d - kRx];
    }
    acc[0] += std::sqrt(s);
  });
  const auto cf = block_sum<2>(contacts_.size(), [&](std::size_t ci, std::array<double, 2>& acc) {
    double f = outputs_[ci].force.norm();
    if (with_moments && outputs_[ci].moment.squaredNorm() > 0) {
      const Contact& c = contacts_[ci];
      double r = balls.radius[static_cast<std::size_t>(c.end1)];
      if (c.kind == ContactKind::BallBall)
        r = 0.5 * (r + balls.radius[static_cast<std::size_t>(c.end2)]);
      f = std::hypot(f, outputs_[ci].moment.norm() / r);
    }
    if (f > 0) {
      acc[0] += f;
      acc[1] += 1;
    }
  });
  double ub_sum = ub[0];
  std::size_t bodies = balls.size();
  for (const Clump& c : clumps) {
    Vec3 F = c.mass * settings.gravity + c.applied_force;
    for (std::int32_t p : c.pebbles)
      F += balls.force[static_cast<std::size_t>(p)];
    if (settings.dim == 2)
      F.z() = 0;
    ub_sum += F.norm();
    bodies -= c.pebbles.size() - 1;
  }
  const double mean_ub = bodies ? ub_sum / static_cast<double>(bodies) : 0.0;
  const double mean_cf = cf[1] > 0 ? cf[0] / cf[1] : 0.0;
  if (mean_cf <= 0)
    return mean_ub > 0 ? std::numeric_limits<double>::infinity() : 0.0;
  return mean_ub / mean_cf;
}

void Model::drain_events(std::vector<Event>& out) {
  out.insert(out.end(), pending_events_.begin(), pending_events_.end());
  pending_events_.clear();
}

Eigen::Matrix3d Model::average_stress(double volume) const {
  // sigma = (1/V) sum over balls and their contacts of (x_c - x_b) (x) f, tension positive.
  Eigen::Matrix3d s = Eigen::Matrix3d::Zero();
  for (std::size_t ci = 0; ci < contacts_.size(); ++ci) {
    const Contact& c = contacts_[ci];
    const ContactOutput& o = outputs_[ci];
    s -= (o.xc - balls.pos[static_cast<std::size_t>(c.end1)]) * o.force.transpose();
    if (c.kind == ContactKind::BallBall)
      s += (o.xc - balls.pos[static_cast<std::size_t>(c.end2)]) * o.force.transpose();
  }
  s /= volume;
  return 0.5 * (s + s.transpose());
}

std::size_t Model::active_contact_count() const {
  std::size_t count = 0;
  for (const ContactOutput& o : outputs_)
    if (o.force != Vec3::Zero() || o.moment != Vec3::Zero())
      ++count;
  return count;
}

} // namespace rocklab
