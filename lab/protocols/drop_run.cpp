// One drop of the drop test: the rock (a clump, or pebbles joined by bonds) is released just above
// a rigid platen at the speed that reaches the impact speed, and followed until it leaves the
// platen for good; restitution by velocity and by energy (thesis Eq. 24) and the energy lost.
#include "lab/protocols/drop.hpp"

#include "core/model.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

namespace rocklab {

namespace {

/// The rock as one body: a clump, or the bonded balls' centre of mass.
struct RockState {
  Vec3 pos = Vec3::Zero(), vel = Vec3::Zero(), spin = Vec3::Zero();
  double ke = 0, ke_rot = 0; ///< kinetic energy, total and rotational [J]
};

RockState rock_state(const Model& m, bool bonded) {
  if (!bonded) {
    const Clump& k = m.clumps[0];
    return {k.pos, k.vel, k.spin, k.kinetic_translational() + k.kinetic_rotational(),
            k.kinetic_rotational()};
  }
  double mass = 0;
  Vec3 x = Vec3::Zero(), v = Vec3::Zero();
  for (std::size_t i = 0; i < m.balls.size(); ++i) {
    mass += m.balls.mass[i];
    x += m.balls.mass[i] * m.balls.pos[i];
    v += m.balls.mass[i] * m.balls.vel[i];
  }
  x /= mass;
  v /= mass;
  Vec3 L = Vec3::Zero();
  double I = 0, ke = 0;
  for (std::size_t i = 0; i < m.balls.size(); ++i) {
    const Vec3 r = m.balls.pos[i] - x;
    L += m.balls.mass[i] * r.cross(m.balls.vel[i] - v) + m.balls.inertia[i] * m.balls.spin[i];
    I += m.balls.mass[i] * r.squaredNorm() + m.balls.inertia[i];
    ke += 0.5 * m.balls.mass[i] * m.balls.vel[i].squaredNorm() +
          0.5 * m.balls.inertia[i] * m.balls.spin[i].squaredNorm();
  }
  const double ke_rot = ke - 0.5 * mass * v.squaredNorm();
  return {x, v, L / I, ke, ke_rot}; // spin: the mean angular velocity about the centre of mass
}

/// The model of one drop: the platen (normal `up` through the origin) and the rock released
/// release_gap above it at the speed that reaches `speed` at the platen. Sets r.exponent.
std::unique_ptr<Model> drop_model(const DropProtocol& p, double speed, double exponent,
                                  DropResult& r) {
  const int dim = p.dim;
  const Vec3 up = dim == 2 ? Vec3::UnitY() : Vec3::UnitZ();
  auto model = std::make_unique<Model>();
  Model& m = *model;
  m.settings.dim = dim;
  m.settings.gravity = -p.gravity * up;
  m.settings.local_damping = p.local_damping;
  m.settings.timestep_safety = p.timestep_safety;
  double lowest = std::numeric_limits<double>::infinity(), size = 0;
  for (const Pebble& q : p.rock) {
    lowest = std::min(lowest, q.position.dot(up) - q.radius);
    size = std::max(size, q.position.norm() + q.radius);
  }
  m.walls.push_back(plane_wall(dim, "platen", Vec3::Zero(), up, 200 * size));
  ModelRule rule;
  rule.ball_facet = true;
  rule.props = p.contact;
  if (auto* pp = std::get_if<PowerPlasticProps>(&rule.props)) {
    if (exponent > 0)
      pp->pp_b = exponent;
    r.exponent = pp->pp_b;
  }
  m.rules.push_back(rule);
  std::vector<Pebble> rock = p.rock;
  for (Pebble& q : rock)
    q.position += (p.release_gap - lowest) * up;
  const double v0 = std::sqrt(std::max(0.0, speed * speed - 2 * p.gravity * p.release_gap));
  const int g = m.group_index("rock");
  if (p.bonded) {
    ModelRule bb;
    bb.props = p.bond;
    m.rules.push_back(bb);
    for (std::size_t k = 0; k < rock.size(); ++k) {
      const std::size_t i = m.balls.add(dim, static_cast<std::int64_t>(k) + 1, rock[k].position,
                                        rock[k].radius, p.density, g);
      m.balls.vel[i] = -v0 * up;
    }
  } else {
    m.add_clump(rock, p.density, g, 1, 1, -v0 * up, Vec3::Zero());
  }
  m.initialize();
  m.settings.slip_events = false;
  return model;
}

/// Fragments of a bonded rock: balls joined by unbroken bonds (union-find over the bonded
/// contacts); their masses, largest first [kg].
std::vector<double> fragment_masses(const Model& m) {
  std::vector<std::size_t> parent(m.balls.size());
  for (std::size_t i = 0; i < parent.size(); ++i)
    parent[i] = i;
  auto root = [&](std::size_t i) {
    while (parent[i] != i)
      i = parent[i] = parent[parent[i]];
    return i;
  };
  for (const Contact& k : m.contacts()) {
    if (k.kind != ContactKind::BallBall)
      continue;
    const bool intact = contact_bond_view(m.batches(), k.model, k.slot).intact > 0;
    if (intact)
      parent[root(static_cast<std::size_t>(k.end1))] = root(static_cast<std::size_t>(k.end2));
  }
  std::vector<double> mass(parent.size(), 0.0);
  for (std::size_t i = 0; i < parent.size(); ++i)
    mass[root(i)] += m.balls.mass[i];
  std::vector<double> out;
  for (double x : mass)
    if (x > 0)
      out.push_back(x);
  std::sort(out.begin(), out.end(), std::greater<>());
  return out;
}

/// Follows the rock's contact with the platen: the first touch, each departure, and the rebound
/// (a departure after which the rock rises by 2 % of its smallest radius, or turns down, without
/// touching again).
struct Bounce {
  Bounce(const Vec3& up_axis, double min_radius) : up(up_axis), rmin(min_radius) {}

  Vec3 up;
  double rmin;
  bool touched = false, was = false, candidate = false, done = false;
  double t_first = 0, snap_height = 0;
  DropResult snap;     ///< the rock's state when it last left the platen
  EnergyLedger e_snap; ///< the model's energies then

  void step(const Model& m, const RockState& c, bool t, DropResult& r) {
    if (touched) {
      if (t && !was) {
        ++r.touches;
        candidate = false;
      }
      if (!t && was) {
        // The rock just left: keep its state; it is the rebound unless the rock touches again.
        candidate = true;
        snap_height = c.pos.dot(up);
        snap.v_rebound = c.vel.dot(up);
        snap.v_tangential = (c.vel - c.vel.dot(up) * up).norm();
        snap.spin = c.spin.norm();
        snap.ke_after = c.ke;
        snap.ke_rotational_after = c.ke_rot;
        snap.contact_time = m.time() - t_first;
        e_snap = m.energy();
      }
      if (!t && candidate && (c.vel.dot(up) <= 0 || c.pos.dot(up) - snap_height >= 0.02 * rmin)) {
        done = snap.v_rebound > 0;
        candidate = done;
      }
    }
    was = t;
  }
};

bool touching(const Model& m) {
  for (const Contact& k : m.contacts())
    if (k.kind == ContactKind::BallFacet && k.gap < 0)
      return true;
  return false;
}

} // namespace

WorkEstimate drop_estimate(const DropProtocol& p) {
  // Each drop runs to its rebound or to max_time, at the time step of its model (the same for
  // every speed: it follows from the contact and the rock); counted to max_time, a bound (the
  // shipped rockfall rebounds within a third of it). A calibration fits b in about 5 drops per
  // speed (the shipped one: 81 drops for 15 speeds) plus the fitted drop with its history rows.
  DropResult r;
  const std::unique_ptr<Model> m = drop_model(p, p.speeds.front(), 0, r);
  const double speeds = static_cast<double>(p.speeds.size());
  const double dt = m->estimate_timestep();
  const double per_drop = dt > 0 ? p.max_time / dt : 0;
  WorkEstimate e;
  e.steps = speeds * (p.calibrate ? 6.0 : 1.0) * per_drop;
  e.ball_steps = e.steps * static_cast<double>(m->balls.size());
  e.bytes = speeds * (per_drop / static_cast<double>(p.history_every) + 2) * 120; // rows' text
  return e;
}

DropResult run_drop(const DropProtocol& p, double speed, double exponent, std::string* history) {
  DropResult r;
  r.speed = speed;
  const std::unique_ptr<Model> model = drop_model(p, speed, exponent, r);
  Model& m = *model;
  const Vec3 up = p.dim == 2 ? Vec3::UnitY() : Vec3::UnitZ();
  double rmin = std::numeric_limits<double>::infinity();
  for (const Pebble& q : p.rock)
    rmin = std::min(rmin, q.radius);
  const std::size_t g = static_cast<std::size_t>(m.group_index("rock"));
  std::vector<Event> events;
  RockState c = rock_state(m, p.bonded);
  EnergyLedger e0 = m.energy();
  Vec3 prev_vel = c.vel;
  double prev_ke = c.ke;
  Bounce b(up, rmin);
  auto row = [&] {
    if (!history)
      return;
    const EnergyLedger ge = m.group_energy()[g];
    char buf[512];
    std::snprintf(buf, sizeof buf, "%.6g,%.9g,%lld,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n",
                  speed, m.time(), static_cast<long long>(m.step()), ge.kinetic(),
                  ge.kinetic_rotational, ge.strain, ge.plastic, ge.slip, ge.body_work,
                  c.pos.dot(up), c.vel.dot(up));
    *history += buf;
  };
  row();
  while (m.time() < p.max_time && !b.done) {
    if (!b.touched) {
      prev_vel = c.vel;
      prev_ke = c.ke;
      e0 = m.energy();
    }
    m.cycle(1);
    events.clear();
    m.drain_events(events);
    for (const Event& ev : events)
      r.bonds_broken += ev.type == EventType::BondBreak ? 1 : 0;
    c = rock_state(m, p.bonded);
    const bool t = touching(m);
    r.max_force = std::max(r.max_force, m.walls[0].force.norm());
    if (!b.touched && t) {
      b.touched = true;
      r.touches = 1;
      b.t_first = m.time();
      r.v_impact = -prev_vel.dot(up);
      r.ke_before = prev_ke;
      b.was = t;
    } else {
      b.step(m, c, t, r);
    }
    if (m.step() % p.history_every == 0)
      row();
  }
  row();
  r.steps = m.step();
  if (p.bonded)
    r.fragments = fragment_masses(m);
  if (!b.done) {
    // Still on the platen (or never reached it) at max_time: no rebound.
    b.e_snap = m.energy();
    b.snap = DropResult{};
    b.snap.ke_after = c.ke;
    b.snap.contact_time = b.touched ? m.time() - b.t_first : 0;
  }
  r.rebounded = b.done;
  r.v_rebound = b.snap.v_rebound;
  r.v_tangential = b.snap.v_tangential;
  r.spin = b.snap.spin;
  r.ke_after = b.snap.ke_after;
  r.ke_rotational_after = b.snap.ke_rotational_after;
  r.contact_time = b.snap.contact_time;
  r.e_velocity = r.v_impact > 0 ? r.v_rebound / r.v_impact : 0;
  r.e_energy = r.ke_before > 0 && b.done ? std::sqrt(r.ke_after / r.ke_before) : 0; // Eq. 24
  r.plastic = b.e_snap.plastic - e0.plastic;
  r.slip = b.e_snap.slip - e0.slip;
  r.dashpot = b.e_snap.dashpot - e0.dashpot;
  r.damping = b.e_snap.local_damping - e0.local_damping;
  r.bond_break = b.e_snap.bond_break - e0.bond_break;
  return r;
}

} // namespace rocklab
