// Genesis stage "floaters": grains with fewer than 3 (3D) or 2 (2D) force-carrying contacts are
// counted (and removed if the card asks); the coordination number is counted without them.
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

} // namespace rocklab::genesis
