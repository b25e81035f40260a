// Genesis stage "packing": the packing contacts (linear springs at the card's stiffness for the
// mean grain size, softened for compaction, frictionless at first) and the cloud relaxed until its
// overlaps are small.
#include "contact/linear.hpp"
#include "materials/genesis/stages.hpp"

#include <algorithm>

namespace rocklab::genesis {

namespace {

double max_overlap_ratio(const Model& m) {
  double worst = 0;
  for (const Contact& c : m.contacts()) {
    if (c.kind != ContactKind::BallBall || c.gap >= 0)
      continue;
    const double r = std::min(m.balls.radius[static_cast<std::size_t>(c.end1)],
                              m.balls.radius[static_cast<std::size_t>(c.end2)]);
    worst = std::max(worst, -c.gap / r);
  }
  return worst;
}

} // namespace

double packing_margin(const MaterialCard& card, double r_avg) {
  return card.packing_margin_ratio > 0 ? card.packing_margin_ratio * r_avg
                                       : std::max(0.05 * r_avg, card.install_gap);
}

void relax_cloud(Run& g) {
  Model& m = g.m;
  const MaterialCard& card = g.card;
  GenesisReport& rep = g.rep;
  const int dim = card.dim;
  const double r_avg = g.r_avg;
  // Packing contacts: linear springs with the card's stiffness at the mean size; frictionless
  // for the cloud relaxation, then the packing friction between grains. Vessel walls stay
  // frictionless.
  LinearProps pack;
  if (card.linear.emod > 0) {
    const double area = linear::deformability_area(dim, r_avg);
    pack.kn = area * card.linear.emod / (2 * r_avg);
    pack.ks = card.linear.kratio > 0 ? pack.kn / card.linear.kratio : 0;
  } else {
    pack.kn = card.linear.kn;
    pack.ks = card.linear.ks;
  }
  pack.fric = 0;
  // Compaction runs with springs soft enough that the pressure strains them by
  // `compaction_strain` (the rearrangement takes ~sqrt(E*/p) steps, so stiff rock contacts
  // would make it slow); the card's stiffness is installed once the porosity is locked.
  g.stiff = pack;
  {
    const double area = linear::deformability_area(dim, r_avg);
    const double e_equiv = pack.kn * 2 * r_avg / area;
    const double f = std::min(1.0, card.pressure / (card.compaction_strain * e_equiv));
    pack.kn *= f;
    pack.ks *= f;
  }
  ModelRule bb, bf;
  bb.props = pack;
  bf.ball_facet = true;
  LinearProps pack_wall = pack;
  pack_wall.kn *= 2; // L = R for a facet
  pack_wall.ks *= 2;
  bf.props = pack_wall;
  m.rules = {bb, bf};
  m.settings.margin = packing_margin(card, r_avg);
  m.settings.overlap_check = false; // a cloud overlaps by design
  m.initialize();

  g.say("relaxing the grain cloud");
  rep.steps_packing += g.run_until("cloud relaxation", 50,
                                   [&] { return max_overlap_ratio(m) <= card.max_overlap_ratio; });
  if (!g.contraction)
    for (std::size_t i = 0; i < m.balls.size(); ++i)
      m.balls.set_radius(i, g.radii[i], dim);
  m.settings.overlap_check = true;
}

} // namespace rocklab::genesis
