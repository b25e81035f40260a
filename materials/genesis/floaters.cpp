// Genesis stage "floaters": grains with fewer than 3 (3D) or 2 (2D) force-carrying contacts are
// counted (and removed if the card asks); the coordination number is counted without them. Also
// the grains that escaped the vessel are removed.
#include "materials/genesis/stages.hpp"

#include <algorithm>

namespace rocklab::genesis {

void remove_floaters(Run& g) {
  Model& m = g.m;
  const MaterialCard& card = g.card;
  GenesisReport& rep = g.rep;
  const int dim = card.dim;
  auto count_contacts = [&]() {
    std::vector<int> n(m.balls.size(), 0);
    for (std::size_t ci = 0; ci < m.contacts().size(); ++ci) {
      const Contact& c = m.contacts()[ci];
      if (m.contact_outputs()[ci].force == Vec3::Zero())
        continue;
      ++n[static_cast<std::size_t>(c.end1)];
      if (c.kind == ContactKind::BallBall)
        ++n[static_cast<std::size_t>(c.end2)];
    }
    return n;
  };
  {
    const std::vector<int> n = count_contacts();
    std::vector<bool> floater(m.balls.size(), false);
    for (std::size_t i = 0; i < n.size(); ++i)
      floater[i] = n[i] < (dim == 3 ? 3 : 2);
    rep.floaters = std::count(floater.begin(), floater.end(), true);
    std::int64_t bb = 0;
    for (std::size_t ci = 0; ci < m.contacts().size(); ++ci) {
      const Contact& c = m.contacts()[ci];
      if (c.kind == ContactKind::BallBall && m.contact_outputs()[ci].force != Vec3::Zero() &&
          !floater[static_cast<std::size_t>(c.end1)] && !floater[static_cast<std::size_t>(c.end2)])
        ++bb;
    }
    const double live = static_cast<double>(m.balls.size()) - static_cast<double>(rep.floaters);
    rep.coordination = live > 0 ? 2.0 * static_cast<double>(bb) / live : 0;
    if (card.eliminate_floaters && rep.floaters > 0)
      m.remove_balls(floater);
  }
}

void remove_escaped(Run& g) {
  // Relaxing a random cloud can squeeze a grain so hard against a vessel wall that its centre
  // crosses the wall's plane; the two-sided wall then pushes it out and it flies off with no
  // contact. Left in place it ends up in the specimen file tens of millimetres from the rock,
  // where the lab's platens (placed at the outermost grains) would start from it and hit the
  // specimen at the seating servo's full speed. Such grains are not part of the rock: remove them.
  Model& m = g.m;
  std::vector<bool> out(m.balls.size(), false);
  std::int64_t n = 0;
  for (std::size_t i = 0; i < m.balls.size(); ++i)
    if (!g.vessel.holds(m, m.balls.pos[i])) {
      out[i] = true;
      ++n;
    }
  if (n > 0) {
    m.remove_balls(out);
    g.rep.escaped += n;
    if (g.rep.porosity_installed > 0) // after installation: what it reached, without them
      g.rep.porosity = g.rep.porosity_installed = g.porosity_now();
  }
}

} // namespace rocklab::genesis
