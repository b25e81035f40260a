// Genesis stage "release": the vessel is unloaded quasi-statically and removed, the locked-in
// stresses relax; a test shape is cut from the block if the card asks, and the residual stress
// and the specimen's porosity are reported.
#include "materials/genesis/stages.hpp"

#include <algorithm>

namespace rocklab::genesis {

void release(Run& g) {
  Model& m = g.m;
  const MaterialCard& card = g.card;
  GenesisReport& rep = g.rep;
  const int dim = card.dim;
  const double p = card.pressure;
  // Release: unload the vessel quasi-statically, remove it, relax the locked-in stresses.
  g.say("releasing the vessel");
  {
    const std::int64_t start = m.step();
    const int ramp = 20;
    for (int k = ramp - 1; k >= 0; --k) {
      const double target = p * k / ramp;
      for (int c = 0; c < 100; ++c) {
        g.servo_step(std::max(target, 1e-6 * p));
        m.cycle(1);
      }
      m.clear_events();
      g.check_interrupt();
    }
    for (Wall& w : m.walls) {
      w.velocity.setZero();
      w.radial_velocity = 0;
    }
    std::vector<bool> all(m.walls.size(), true);
    m.remove_walls(all);
    g.run_until("release", 50,
                [&] { return m.mean_unbalanced_force_ratio() <= card.equilibrium_ratio; });
    if (card.cut) {
      std::vector<bool> outside(m.balls.size());
      for (std::size_t i = 0; i < m.balls.size(); ++i)
        outside[i] = !card.cut->contains(m.balls.pos[i]);
      m.remove_balls(outside);
      g.run_until("release after cutting", 50,
                  [&] { return m.mean_unbalanced_force_ratio() <= card.equilibrium_ratio; });
    }
    rep.steps_release = m.step() - start;
  }
  const double V_final = card.cut ? card.cut->volume(dim) : g.installed_volume;
  if (card.cut) // grains whose centres lie inside count whole: an unbiased volume fraction
    rep.porosity = 1 - grain_volume_sum(m) / V_final;
  {
    const Eigen::Matrix3d s = m.average_stress(V_final);
    rep.residual_mean_stress = -s.trace() / dim;
  }
}

} // namespace rocklab::genesis
