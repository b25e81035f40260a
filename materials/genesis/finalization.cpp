// Genesis stage "finalization": grain-grain contacts whose gap is within the installation gap
// g_i get the card's bonded model (flat joints bonded, gapped or slit by the card's fractions;
// parallel or contact bonds), with strengths drawn per contact; every other contact and every new
// one is linear.
#include "materials/genesis/stages.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace rocklab::genesis {

namespace {

// Where a bonded contact's random values come from: the run's stream (in shuffled contact order,
// the types by rank) or, with `installation.draws` "per_contact", a stream of the contact's own
// seeded from the card's seed and the contact key, the type from a uniform quantile.
class Draws {
public:
  explicit Draws(std::mt19937_64& run) : rng_(&run) {}
  Draws(std::uint64_t seed, std::uint64_t key) : own_(mix(seed ^ mix(key))), per_contact_(true) {
    type_u_ = uniform01(own_);
  }
  double normal(const Distribution& dist) {
    if (!per_contact_)
      return genesis::normal(*rng_, dist);
    // Always two uniforms, so the later draws do not depend on whether this sd is zero.
    const double u1 = std::max(uniform01(own_), 1e-300), u2 = uniform01(own_);
    const double z = std::sqrt(-2 * std::log(u1)) * std::cos(2 * std::numbers::pi * u2);
    return dist.sd > 0 ? std::max(0.0, dist.mean + dist.sd * z) : dist.mean;
  }
  /// 0 bonded, 1 gapped, 2 slit: by the contact's own uniform against the card's fractions, or
  /// by its rank k among the shuffled candidates against the rounded counts.
  int type(std::size_t k, std::size_t n_bonded, std::size_t n_gapped, double f_bonded,
           double f_gapped) const {
    if (per_contact_)
      return type_u_ < f_bonded ? 0 : (type_u_ < f_bonded + f_gapped ? 1 : 2);
    return k < n_bonded ? 0 : (k < n_bonded + n_gapped ? 1 : 2);
  }

private:
  static std::uint64_t mix(std::uint64_t x) { // splitmix64's finalizer
    x += 0x9e3779b97f4a7c15ULL;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
    return x ^ (x >> 31);
  }
  std::mt19937_64 own_;
  std::mt19937_64* rng_ = nullptr; ///< the run's stream (sequence mode only)
  bool per_contact_ = false;
  double type_u_ = 0;
};

} // namespace

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
  if (!card.per_contact_draws)
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
    // Per-contact draws: a stream of the contact's own (the seed and the grain pair): one uniform
    // for the type, then two uniforms per strength, whatever the card's values.
    Draws d = card.per_contact_draws ? Draws(card.seed, m.contacts()[ci].key) : Draws(g.rng);
    if (card.bonding == MaterialCard::Bonding::FlatJoint) {
      FlatJointProps fj = card.fj;
      fj.fj_ten = d.normal(card.fj_ten);
      fj.fj_coh = d.normal(card.fj_coh);
      const int type = d.type(k, n_bonded, n_gapped, card.frac_bonded, card.frac_gapped);
      if (type == 0) {
        fj.bond = true;
        fj.fj_gap0 = 0;
        ++rep.fj_bonded;
      } else if (type == 1) {
        fj.bond = false;
        fj.fj_gap0 = std::max(d.normal(card.gapped_gap), 1e-12 * r_avg);
        ++rep.fj_gapped;
      } else {
        fj.bond = false;
        fj.fj_gap0 = 0;
        ++rep.fj_slit;
      }
      m.replace_contact_model(ci, fj);
    } else if (card.bonding == MaterialCard::Bonding::ParallelBond) {
      LinearPBondProps pb = card.pb;
      pb.pb_ten = d.normal(card.pb_ten);
      pb.pb_coh = d.normal(card.pb_coh);
      install_bond(ci, pb, rep.pb_bonded);
    } else if (card.bonding == MaterialCard::Bonding::ContactBond) {
      ContactBondProps cb;
      // A point bond made across an open gap would start in tension (its normal force is
      // kn (g - g_r)); the reference gap makes the bonded gap the contact's rest state.
      cb.linear.rgap = std::max(m.contacts()[ci].gap, 0.0);
      cb.cb_tenf = d.normal(card.cb_tenf);
      cb.cb_shearf = d.normal(card.cb_shearf);
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
