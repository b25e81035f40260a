// Genesis stage "finalization": grain-grain contacts whose gap is within the installation gap
// g_i get the card's bonded model (flat joints bonded, gapped or slit by the card's fractions;
// parallel or contact bonds), with strengths drawn per contact; every other contact and every new
// one is linear.
#include "materials/genesis/stages.hpp"

#include <algorithm>
#include <cmath>

namespace rocklab::genesis {

void finalize_contacts(Run& g) {
  Model& m = g.m;
  const MaterialCard& card = g.card;
  GenesisReport& rep = g.rep;
  const double r_avg = g.r_avg;
  // Finalization: bonds at grain-grain contacts with gap <= g_i, linear elsewhere.
  g.say("finalizing");
  m.set_margin(std::max(m.margin(), g.install_gap * 1.01));
  std::vector<std::size_t> candidates;
  for (std::size_t ci = 0; ci < m.contacts().size(); ++ci) {
    const Contact& c = m.contacts()[ci];
    if (c.kind == ContactKind::BallBall && c.gap <= g.install_gap)
      candidates.push_back(ci);
  }
  for (std::size_t i = candidates.size(); i > 1; --i) // seeded Fisher-Yates shuffle
    std::swap(candidates[i - 1],
              candidates[static_cast<std::size_t>(uniform01(g.rng) * static_cast<double>(i))]);
  const std::size_t N = candidates.size();
  const std::size_t n_bonded =
      static_cast<std::size_t>(std::llround(card.frac_bonded * static_cast<double>(N)));
  const std::size_t n_gapped =
      std::min(N - n_bonded,
               static_cast<std::size_t>(std::llround(card.frac_gapped * static_cast<double>(N))));
  std::vector<bool> is_bond(m.contacts().size(), false);
  // A bonded model (parallel or contact bond) on the card's linear component, bonded now.
  auto install_bond = [&](std::size_t ci, auto props, std::int64_t& count) {
    const double rgap = props.linear.rgap;
    props.linear = card.linear;
    props.linear.rgap = rgap;
    props.bond = true;
    props.bond_gap_lo = -1e300;
    props.bond_gap_hi = 1e300; // the candidate test above already applied g <= g_i
    m.replace_contact_model(ci, props);
    ++count;
  };
  for (std::size_t k = 0; k < N; ++k) {
    const std::size_t ci = candidates[k];
    is_bond[ci] = true;
    if (card.bonding == MaterialCard::Bonding::FlatJoint) {
      FlatJointProps fj = card.fj;
      fj.fj_ten = normal(g.rng, card.fj_ten);
      fj.fj_coh = normal(g.rng, card.fj_coh);
      if (k < n_bonded) {
        fj.bond = true;
        fj.fj_gap0 = 0;
        ++rep.fj_bonded;
      } else if (k < n_bonded + n_gapped) {
        fj.bond = false;
        fj.fj_gap0 = std::max(normal(g.rng, card.gapped_gap), 1e-12 * r_avg);
        ++rep.fj_gapped;
      } else {
        fj.bond = false;
        fj.fj_gap0 = 0;
        ++rep.fj_slit;
      }
      m.replace_contact_model(ci, fj);
    } else if (card.bonding == MaterialCard::Bonding::ParallelBond) {
      LinearPBondProps pb = card.pb;
      pb.pb_ten = normal(g.rng, card.pb_ten);
      pb.pb_coh = normal(g.rng, card.pb_coh);
      install_bond(ci, pb, rep.pb_bonded);
    } else if (card.bonding == MaterialCard::Bonding::ContactBond) {
      ContactBondProps cb;
      // A point bond made across an open gap would start in tension (its normal force is
      // kn (g - g_r)); the reference gap makes the bonded gap the contact's rest state.
      cb.linear.rgap = std::max(m.contacts()[ci].gap, 0.0);
      cb.cb_tenf = normal(g.rng, card.cb_tenf);
      cb.cb_shearf = normal(g.rng, card.cb_shearf);
      install_bond(ci, cb, rep.cb_bonded);
    } else {
      is_bond[ci] = false;
    }
  }
  for (std::size_t ci = 0; ci < m.contacts().size(); ++ci)
    if (!is_bond[ci]) {
      LinearProps lp = card.linear;
      m.replace_contact_model(ci, lp);
    }
  ModelRule new_bb, new_bf;
  new_bb.props = card.linear;
  new_bf.ball_facet = true;
  new_bf.props = card.linear;
  m.rules = {new_bb, new_bf};
}

} // namespace rocklab::genesis
