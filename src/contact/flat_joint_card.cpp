// A material card's flat joints (card_bonding.hpp): the card's "flatjoint" section, whose
// candidates are bonded, gapped or slit by the card's type fractions, with tension, cohesion
// and a gapped contact's gap drawn per contact. Units SI.
#include "contact/card_bonding.hpp"
#include "contact/flat_joint.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

namespace rocklab {

namespace {

class FlatJointCard final : public CardBonding {
public:
  FlatJointCard(JsonObject& top, int dim) {
    std::vector<Distribution> drawn;
    fj_ = read_card_section<FlatJoint>(
        top, "flatjoint", dim, "fj_", {"types"},
        {{"fj_ten", &FlatJointProps::fj_ten, "Pa"}, {"fj_coh", &FlatJointProps::fj_coh, "Pa"}},
        &drawn);
    ten_ = drawn[0];
    coh_ = drawn[1];
    JsonObject f = top.object("flatjoint");
    if (!(fj_.fj_emod > 0 || fj_.fj_kn > 0))
      f.fail("fj_emod", "missing: a card's flat joints need a stiffness (fj_emod with fj_kratio, "
                        "or fj_kn with fj_ks)");
    if (f.has("fj_gap0"))
      f.fail("fj_gap0", "is set by genesis on a card: give the gapped contacts' gap as "
                        "'types.gap'");
    JsonObject t = f.optional_object("types");
    fractions_ = {t.number("bonded", Range::closed(0, 1), 1.0),
                  t.number("gapped", Range::closed(0, 1), 0.0),
                  t.number("slit", Range::closed(0, 1), 0.0)};
    const double sum = fractions_[0] + fractions_[1] + fractions_[2];
    if (std::abs(sum - 1) > 1e-9)
      t.fail("bonded", "the fractions bonded + gapped + slit must sum to 1 (they sum to " +
                           std::to_string(sum) + ")");
    // A gapped fraction of 0 may keep its gap (a calibration moving the fraction to its bound).
    if (fractions_[1] > 0 || t.has("gap"))
      gap_ = read_distribution(t, "gap", "m");
    t.finish();
  }

  // Draws: tension, cohesion, the type, then a gapped contact's gap.
  CardBond bond(BondDraws& d, const BondSite& site) const override {
    FlatJointProps fj = fj_;
    fj.fj_ten = d.normal(ten_);
    fj.fj_coh = d.normal(coh_);
    const int type = d.category(fractions_);
    fj.bond = type == 0;
    fj.fj_gap0 = type == 1 ? std::max(d.normal(gap_), 1e-12 * site.r_avg) : 0.0;
    return {fj, FlatJoint::card_counts[type]};
  }
  ModelProps props() const override {
    FlatJointProps fj = fj_;
    fj.fj_ten = ten_.mean;
    fj.fj_coh = coh_.mean;
    return fj;
  }
  std::vector<std::pair<std::string, Distribution>> distributions() const override {
    std::vector<std::pair<std::string, Distribution>> v{{"fj_ten", ten_}, {"fj_coh", coh_}};
    if (fractions_[1] > 0)
      v.emplace_back("types.gap", gap_);
    return v;
  }

private:
  FlatJointProps fj_;
  Distribution ten_, coh_, gap_;
  std::array<double, 3> fractions_{}; ///< bonded, gapped, slit (FlatJoint::card_counts' order)
};

} // namespace

std::unique_ptr<CardBonding> FlatJoint::card_bonding(JsonObject& top, int dim) {
  return std::make_unique<FlatJointCard>(top, dim);
}

} // namespace rocklab
