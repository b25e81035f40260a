// Genesis stage "clumps" (rock-impact thesis Appendix B): before bonding, touching grains are
// joined into rigid clumps of up to the card's clumps.max_pebbles grains.
#include "materials/genesis/stages.hpp"

#include <algorithm>

namespace rocklab::genesis {

void join_clumps(Run& g) {
  Model& m = g.m;
  const MaterialCard& card = g.card;
  GenesisReport& rep = g.rep;
  if (card.clump_max > 1) {
    // Clumps (thesis Appendix B): in a seeded random order, each free grain takes up to
    // clump_max - 1 free grains it touches (in contact order) and the group becomes one rigid
    // body with the grains as pebbles, mass and inertia of their union.
    g.say("joining grains into clumps");
    const std::size_t n = m.balls.size();
    std::vector<std::vector<std::int32_t>> touching(n);
    for (std::size_t ci = 0; ci < m.contacts().size(); ++ci) {
      const Contact& c = m.contacts()[ci];
      if (c.kind == ContactKind::BallBall && c.gap <= 0) {
        touching[static_cast<std::size_t>(c.end1)].push_back(c.end2);
        touching[static_cast<std::size_t>(c.end2)].push_back(c.end1);
      }
    }
    std::vector<std::size_t> order(n);
    for (std::size_t i = 0; i < n; ++i)
      order[i] = i;
    for (std::size_t i = n; i > 1; --i)
      std::swap(order[i - 1],
                order[static_cast<std::size_t>(uniform01(g.rng) * static_cast<double>(i))]);
    std::vector<bool> taken(n, false), remove(n, false);
    std::vector<std::vector<std::size_t>> groups;
    for (std::size_t i : order) {
      if (taken[i])
        continue;
      std::vector<std::size_t> g{i};
      taken[i] = true;
      for (std::int32_t j : touching[i]) {
        if (static_cast<int>(g.size()) >= card.clump_max)
          break;
        if (!taken[static_cast<std::size_t>(j)]) {
          taken[static_cast<std::size_t>(j)] = true;
          g.push_back(static_cast<std::size_t>(j));
        }
      }
      if (g.size() > 1) {
        for (std::size_t k : g)
          remove[k] = true;
        groups.push_back(std::move(g));
      }
    }
    struct Pending {
      std::vector<Pebble> pebbles;
      Vec3 vel;
      int group;
      std::vector<std::int64_t> ids;
    };
    std::vector<Pending> pending;
    for (const auto& g : groups) {
      Pending p;
      p.vel = Vec3::Zero();
      for (std::size_t k : g) {
        p.pebbles.push_back({m.balls.pos[k], m.balls.radius[k]});
        p.vel += m.balls.vel[k] / static_cast<double>(g.size());
        p.ids.push_back(m.balls.id[k]);
      }
      p.group = m.balls.group[g[0]];
      pending.push_back(std::move(p));
    }
    m.remove_balls(remove);
    std::int64_t next_id = 1;
    for (std::int64_t id : m.balls.id)
      next_id = std::max(next_id, id + 1);
    for (const Pending& p : pending)
      for (std::int64_t id : p.ids)
        next_id = std::max(next_id, id + 1);
    std::int64_t clump_id = 1;
    for (const Pending& p : pending) {
      m.add_clump(p.pebbles, card.density, p.group, clump_id++, next_id, p.vel, Vec3::Zero());
      next_id += static_cast<std::int64_t>(p.pebbles.size());
    }
    m.set_margin(m.margin()); // detect the contacts of the new pebbles
    m.cycle(1);
    rep.clumps = static_cast<std::int64_t>(m.clumps.size());
  }
}

} // namespace rocklab::genesis
