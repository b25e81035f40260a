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
// categories by rank) or, with `installation.draws` "per_contact", a stream of the contact's own
// seeded from the card's seed and the contact key, the category from a uniform quantile.
class Draws final : public BondDraws {
public:
  Draws(std::mt19937_64& run, std::size_t rank, std::size_t count)
      : rng_(&run), rank_(rank), count_(count) {}
  Draws(std::uint64_t seed, std::uint64_t key) : own_(mix(seed ^ mix(key))), per_contact_(true) {
    category_u_ = uniform01(own_);
  }
  double normal(const Distribution& dist) override {
    if (!per_contact_)
      return genesis::normal(*rng_, dist);
    // Always two uniforms, so the later draws do not depend on whether this sd is zero.
    const double u1 = std::max(uniform01(own_), 1e-300), u2 = uniform01(own_);
    const double z = std::sqrt(-2 * std::log(u1)) * std::cos(2 * std::numbers::pi * u2);
    return dist.sd > 0 ? std::max(0.0, dist.mean + dist.sd * z) : dist.mean;
  }
  /// By the contact's own uniform against the cumulative fractions, or by its rank among the
  /// shuffled candidates against the rounded counts (each at most what is left).
  int category(std::span<const double> fractions) override {
    const int last = static_cast<int>(fractions.size()) - 1;
    double cumulative = 0;
    std::size_t below = 0;
    for (int i = 0; i < last; ++i) {
      cumulative += fractions[i];
      below += std::min(count_ - below, static_cast<std::size_t>(std::llround(
                                            fractions[i] * static_cast<double>(count_))));
      if (per_contact_ ? category_u_ < cumulative : rank_ < below)
        return i;
    }
    return last;
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
  std::size_t rank_ = 0, count_ = 0;
  bool per_contact_ = false;
  double category_u_ = 0;
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
  std::vector<bool> is_bond(m.contacts().size(), false);
  if (card.bonding)
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      const std::size_t ci = candidates[k];
      is_bond[ci] = true;
      // Per-contact draws: a stream of the contact's own (the seed and the grain pair): one
      // uniform for the category, then two uniforms per strength, whatever the card's values.
      Draws d = card.per_contact_draws ? Draws(card.seed, m.contacts()[ci].key)
                                       : Draws(g.rng, k, candidates.size());
      const CardBond b = card.bonding->bond(d, {m.contacts()[ci].gap, r_avg, &card.linear});
      m.replace_contact_model(ci, b.props);
      ++rep.bonds[GenesisReport::bond_key(model_name(kind_of(b.props)), b.count)];
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
