// Genesis stage "compaction": the servo-controlled vessel compacts the grains at the installation
// pressure with friction control (as in YADE's triaxial compaction): while the packing at
// pressure is looser than the target the grain friction is lowered step by step; at the target
// the packing friction locks the structure, the card's stiffness is installed and the walls hold
// the pressure until equilibrium (material-genesis installation).
#include "materials/genesis/stages.hpp"

#include "io/input_error.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace rocklab::genesis {

namespace {

void set_packing_friction(Model& m, double f) {
  std::get<LinearProps>(m.rules[0].props).fric = f;
  m.set_property(model_kind<Linear>, "fric", f, ContactSelect::BallBall);
}

void install_card_stiffness(Run& g, double fraction = 1.0) {
  Model& m = g.m;
  LinearProps& b = std::get<LinearProps>(m.rules[0].props);
  LinearProps& w = std::get<LinearProps>(m.rules[1].props);
  b.kn = fraction * g.stiff.kn;
  b.ks = fraction * g.stiff.ks;
  w.kn = 2 * b.kn;
  w.ks = 2 * b.ks;
  m.set_property(model_kind<Linear>, "kn", b.kn, ContactSelect::BallBall);
  m.set_property(model_kind<Linear>, "ks", b.ks, ContactSelect::BallBall);
  m.set_property(model_kind<Linear>, "kn", w.kn, ContactSelect::BallFacet);
  m.set_property(model_kind<Linear>, "ks", w.ks, ContactSelect::BallFacet);
}

void stop_walls(Model& m) {
  for (Wall& w : m.walls) {
    w.velocity.setZero();
    w.radial_velocity = 0;
  }
}

// Target reached: lock the structure with the packing friction so that it stops creeping toward
// its frictionless density; the grains come to rest in the held vessel, then the walls hold the
// pressure (at a tenth of the compaction speed).
void lock_packing(Run& g) {
  Model& m = g.m;
  set_packing_friction(m, g.card.packing_friction);
  for (std::size_t i = 0; i < m.balls.size(); ++i) {
    m.balls.vel[i].setZero();
    m.balls.spin[i].setZero();
  }
  stop_walls(m);
  const std::int64_t n = g.card.stiffness_ramp;
  if (n > 0) {
    const double soft = std::get<LinearProps>(m.rules[0].props).kn / g.stiff.kn;
    const std::int64_t stages = 20;
    for (std::int64_t i = 1; i <= stages; ++i) {
      install_card_stiffness(g, std::pow(soft, 1.0 - static_cast<double>(i) / stages));
      for (std::int64_t k = 0; k < n / stages; ++k) {
        g.servo_step(g.card.pressure);
        m.cycle(1);
      }
      m.clear_events();
      g.check_interrupt();
    }
  }
  install_card_stiffness(g);
  g.run_until("settling the locked packing", 50,
              [&] { return m.mean_unbalanced_force_ratio() <= 1e-2; });
  g.speed_cap = 0.001;
}

void say_progress(const Run& g, bool frozen, double n, double ratio) {
  std::ostringstream msg;
  msg << (frozen ? "installing" : "compacting") << ": step " << g.m.step() << ", porosity " << n
      << ", unbalanced-force ratio " << ratio << ", wall stresses [Pa]";
  for (const Servo& s : g.vessel.servos)
    msg << " " << g.vessel.stress(g.m, s);
  g.say(msg.str());
}

[[noreturn]] void porosity_out_of_reach(const MaterialCard& card, double n, bool looser) {
  std::ostringstream msg;
  msg << card.file << ": key 'porosity': the target " << card.porosity;
  if (looser)
    msg << " is looser than the porosity " << n << " that a packing with friction "
        << card.packing_friction
        << " reaches at the installation pressure; raise 'packing.friction'";
  else
    msg << " is below the porosity " << n
        << " that a frictionless packing of these grains reaches at the installation "
           "pressure in this vessel; raise the target or widen the size distribution";
  throw InputError(msg.str());
}

// What installation reached: porosity, wall stresses, the specimen shape.
void record_installation(Run& g) {
  const Model& m = g.m;
  const MaterialCard& card = g.card;
  GenesisReport& rep = g.rep;
  rep.porosity_target = card.porosity;
  rep.porosity = rep.porosity_installed = g.porosity_now();
  stop_walls(g.m);
  for (const Servo& s : g.vessel.servos)
    rep.wall_stress.emplace_back(m.walls[s.wall].name, g.vessel.stress(m, s));
  rep.pressure = card.pressure;
  g.installed_volume = g.vessel.volume(m);
  rep.shape = g.vessel.shape_now(m);
  if (card.cut)
    rep.shape = *card.cut;
}

} // namespace

void compact(Run& g) {
  Model& m = g.m;
  const MaterialCard& card = g.card;
  const double p = card.pressure;
  for (const Servo& s : g.vessel.servos)
    g.largest_half = std::max(g.largest_half, g.vessel.half_extent(m, s));
  g.say("compacting to the target porosity at the installation pressure");
  const std::int64_t start = m.step();
  const std::int64_t chunk = 100;
  const double tol_n = card.porosity_tolerance;
  bool frozen = false;
  std::int64_t frozen_at = 0, window_at = m.step(), decrements = 0;
  double mu = card.packing_friction;
  set_packing_friction(m, mu);
  double n_window = 1.0;
  for (;;) {
    for (std::int64_t k = 0; k < chunk; ++k) {
      g.servo_step(p);
      m.cycle(1);
    }
    m.clear_events();
    g.check_interrupt();
    const double n = g.porosity_now();
    const double ratio = m.mean_unbalanced_force_ratio();
    const bool settled =
        g.stresses_within(p, card.pressure_tolerance) && ratio <= card.equilibrium_ratio;
    // Frictionless compaction has stalled when, at pressure, the porosity moved less than a
    // twentieth of the tolerance over the last 5000 steps.
    bool stalled = false;
    if (m.step() - window_at >= 5000) {
      stalled = g.stresses_within(p, 0.05) && n_window - n < 0.05 * tol_n;
      n_window = n;
      window_at = m.step();
    }
    if ((m.step() - start) % 5000 < chunk)
      say_progress(g, frozen, n, ratio);
    const bool at_pressure = g.stresses_within(p, 0.1);
    if (!frozen && n <= card.porosity + 0.25 * tol_n && at_pressure) {
      if (decrements == 0 && n < card.porosity - tol_n)
        porosity_out_of_reach(card, n, true);
      frozen = true;
      frozen_at = m.step();
      g.rep.porosity_packed = n;
      g.rep.packing_friction = mu;
      lock_packing(g);
    } else if (!frozen && at_pressure && mu > 0 && n > card.porosity) {
      // Too loose at pressure: lower the grain friction a little (the packing follows).
      mu = mu > 0.01 * card.packing_friction ? 0.97 * mu : 0.0;
      set_packing_friction(m, mu);
      ++decrements;
    } else if (!frozen && mu == 0 && (settled || stalled)) {
      porosity_out_of_reach(card, n, false);
    }
    if (frozen && settled)
      break;
    if (m.step() - start > card.max_cycles)
      throw std::runtime_error(card.file + ": the vessel did not reach the installation pressure " +
                               std::to_string(p) + " Pa at the target porosity in " +
                               std::to_string(card.max_cycles) +
                               " cycles (key 'packing.max_cycles')");
  }
  g.rep.steps_packing += frozen_at - start;
  g.rep.steps_installation = m.step() - frozen_at;
  record_installation(g);
}

} // namespace rocklab::genesis
