// The force-displacement stage: every contact updates its plane and its model (in parallel, each
// writing only its own record), then the forces are summed onto balls and walls in a fixed order.
#include "core/model.hpp"

#include "core/geometry.hpp"
#include "core/parallel.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <omp.h>
#include <sstream>

namespace rocklab {

using namespace detail;

void Model::force_displacement(double dt) {
  const std::size_t none = std::numeric_limits<std::size_t>::max();
  std::size_t blowup = none;
  for (auto& buf : thread_events_)
    buf.clear();
  const ThreadPlan& plan = plan_threads();
  for_ranges(plan.contact, [&](std::size_t t, std::size_t begin, std::size_t end) {
    const double start = omp_get_wtime();
    EventBuffer& events = thread_events_[t];
    for (std::size_t ci = begin; ci < end; ++ci)
      if (!update_contact_force(ci, dt, events)) {
#pragma omp critical(rocklab_blowup)
        blowup = std::min(blowup, ci);
      }
    if (static_cast<std::size_t>(omp_get_num_threads()) == plan.threads)
      time_range(t, omp_get_wtime() - start); // each range on its own thread: speeds compare
  });
  balance_threads();
  // Events in a fixed order: by contact, then by the order a contact raised them.
  const std::size_t before = pending_events_.size();
  for (auto& buf : thread_events_)
    pending_events_.insert(pending_events_.end(), buf.begin(), buf.end());
  std::sort(pending_events_.begin() + static_cast<std::ptrdiff_t>(before), pending_events_.end(),
            [](const Event& x, const Event& y) {
              return x.contact != y.contact ? x.contact < y.contact : x.seq < y.seq;
            });
  book_events(before);
  dt_stiffness_ = sum_ball_forces();
  sum_wall_forces();
  if (blowup != none)
    throw_overlap_blowup(blowup);
}

// One contact: the contact plane (Eq. 2, 5), the relative increments (Eq. 7-11), the model's
// update, and the global force and moment. Writes only this contact's records; returns false on
// an overlap beyond a radius (or a non-finite gap).
bool Model::update_contact_force(std::size_t ci, double dt, EventBuffer& events) {
  const int dim = settings.dim;
  Contact& c = contacts_[ci];
  ContactOutput& out = outputs_[ci];
  const std::size_t i1 = static_cast<std::size_t>(c.end1);
  const Vec3& x1 = balls.pos[i1];
  const double R1 = balls.radius[i1];
  PlaneGeometry g;
  Vec3 xb2, v2, w2;
  double R2 = 0, m_eff = inertial_mass(i1);
  if (c.kind == ContactKind::BallBall) {
    const std::size_t i2 = static_cast<std::size_t>(c.end2);
    R2 = balls.radius[i2];
    g = ball_ball_plane(x1, R1, balls.pos[i2], R2);
    xb2 = balls.pos[i2];
    v2 = balls.vel[i2];
    w2 = balls.spin[i2];
    const double m1 = inertial_mass(i1), m2 = inertial_mass(i2);
    m_eff = m1 * m2 / (m1 + m2);
  } else {
    const Wall& wall = walls[static_cast<std::size_t>(c.end2)];
    g = ball_facet_plane(x1, R1, wall.closest_point(x1, &c.facet));
    xb2 = wall.center;
    // A radially moving wall adds its radial speed at the contact point.
    v2 = wall.radial_velocity != 0
             ? Vec3(wall.velocity + wall.radial_velocity * wall.radial_dir(g.xc))
             : wall.velocity;
    w2 = wall.spin;
  }
  const bool fresh = !c.initialized;
  if (fresh) {
    if (dim == 2) {
      c.s = -Vec3::UnitZ();
      c.t = Vec3::UnitZ().cross(g.n);
    } else {
      c.s = initial_s_axis(g.n);
      c.t = g.n.cross(c.s);
    }
    c.initialized = true;
  } else {
    update_plane_axes(dim, c.n, g.n, balls.spin[i1], w2, dt, c.s, c.t);
  }
  // Blow-up: overlap beyond a radius. A facet contact measures an unsigned distance, so
  // there the overlap reaching the radius shows as the normal flipping within one step.
  const bool through = c.kind == ContactKind::BallFacet && !fresh && g.n.dot(c.n) < 0;
  const bool ok =
      !((settings.overlap_check &&
         (g.gap < -std::min(R1, c.kind == ContactKind::BallBall ? R2 : R1) || through)) ||
        !std::isfinite(g.gap));
  out.xc = g.xc;
  c.n = g.n;
  c.gap = g.gap;

  ContactKinematics k;
  k.dt = dt;
  k.dim = dim;
  k.gap = g.gap;
  k.R1 = R1;
  k.R2 = R2;
  k.mass_eff = m_eff;
  k.ball_facet = c.kind == ContactKind::BallFacet;
  relative_increments(out.xc, c.n, c.s, c.t, x1, balls.vel[i1], balls.spin[i1], xb2, v2, w2, dt, k);
  const std::size_t first_event = events.size();
  EventSink sink{&events, c.key, 0, settings.slip_events};
  k.n = c.n;
  k.s = c.s;
  k.t = c.t;
  ContactResult r;
  update_contact(batches_, c.model, c.slot, k, r, sink);
  out.stiff = contact_stiffness(batches_, c.model, c.slot);
  out.force = -r.Fn * c.n + r.Fss * c.s + r.Fst * c.t;
  out.moment = r.Mt * c.n + r.Mbs * c.s + r.Mbt * c.t;
  for (std::size_t e = first_event; e < events.size(); ++e) {
    Event& ev = events[e];
    ev.step = step_;
    ev.time = time_;
    ev.normal = c.n;
    ev.position = out.xc + ev.position.y() * c.s + ev.position.z() * c.t;
    if (ev.gap == 0)
      ev.gap = c.gap;
  }
  return ok;
}

void Model::book_events(std::size_t first) {
  for (std::size_t k = first; k < pending_events_.size(); ++k) {
    const Event& ev = pending_events_[k];
    if (ev.type != EventType::BondBreak || ev.energy == 0)
      continue;
    // The released bond energy leaves the stored partitions: book it, shared like the contact.
    ledger_.bond_break += ev.energy;
    const ContactEnds ends = contact_ends(ev.contact);
    Contact c;
    c.kind = ends.kind;
    c.end1 = ends.end1;
    c.end2 = ends.end2;
    ContactEnergy released;
    released.bond_strain = ev.energy;
    share_contact_energy(c, released, broken_);
  }
}

double Model::sum_ball_forces() {
  // Each ball sums its contacts in contact order; returns the stiffness-limited time step.
  const ThreadPlan& plan = plan_threads();
  range_parts_.resize(plan.threads);
  for_ranges(plan.ball, [&](std::size_t t, std::size_t begin, std::size_t end) {
    double dt_min = std::numeric_limits<double>::infinity();
    for (std::size_t i = begin; i < end; ++i) {
      Vec3 F = Vec3::Zero(), M = Vec3::Zero();
      double k_tran = 0, k_rot = 0;
      const Vec3& xi = balls.pos[i];
      for (std::int32_t a = adj_start_[i]; a < adj_start_[i + 1]; ++a) {
        const std::int32_t item = adj_items_[static_cast<std::size_t>(a)];
        const ContactOutput& c = outputs_[static_cast<std::size_t>(item >> 1)];
        const double side = (item & 1) ? 1.0 : -1.0; // force acts on end2, reaction on end1
        const Vec3 f = side * c.force;
        const Vec3 arm = c.xc - xi;
        F += f;
        M += side * c.moment + arm.cross(f);
        add_ball_stiffness(c.stiff, arm, k_tran, k_rot);
      }
      balls.force[i] = F;
      balls.moment[i] = M;
      if (k_tran > 0)
        dt_min = std::min(dt_min, std::sqrt(inertial_mass(i) / k_tran));
      if (k_rot > 0)
        dt_min = std::min(dt_min, std::sqrt(inertial_inertia(i) / k_rot));
    }
    range_parts_[t][0] = dt_min;
  });
  double dt_min = std::numeric_limits<double>::infinity();
  for (std::size_t t = 0; t < plan.threads; ++t)
    dt_min = std::min(dt_min, range_parts_[t][0]);
  return dt_min;
}

void Model::sum_wall_forces() {
  for (Wall& w : walls) {
    w.force.setZero();
    w.moment.setZero();
    w.radial_force = 0;
  }
  for (const std::int32_t item : facet_contacts_) { // in contact order, as the whole list
    const std::size_t ci = static_cast<std::size_t>(item);
    const Contact& c = contacts_[ci];
    const ContactOutput& o = outputs_[ci];
    Wall& w = walls[static_cast<std::size_t>(c.end2)];
    w.force += o.force;
    w.moment += o.moment + (o.xc - w.center).cross(o.force);
    w.radial_force += o.force.dot(w.radial_dir(o.xc));
  }
}

void Model::throw_overlap_blowup(std::size_t ci) const {
  const Contact& c = contacts_[ci];
  std::ostringstream msg;
  msg << "physical blow-up at step " << step_ << " (t = " << time_
      << " s): overlap beyond a radius at the contact between ball id "
      << balls.id[static_cast<std::size_t>(c.end1)]
      << (c.kind == ContactKind::BallBall ? " and ball id " : " and wall ")
      << (c.kind == ContactKind::BallBall
              ? std::to_string(balls.id[static_cast<std::size_t>(c.end2)])
              : walls[static_cast<std::size_t>(c.end2)].name)
      << " (gap " << c.gap
      << " m, or the ball passed through the wall); reduce the time step, "
         "the loading rate or raise the stiffness";
  throw PhysicsError(msg.str());
}

} // namespace rocklab
