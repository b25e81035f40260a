#include "contact/contact_bond.hpp"

#include "contact/card_bonding.hpp"

#include "io/json_input.hpp"

namespace rocklab {

ContactBond::Contact ContactBond::make(const Props& p, const CreationInfo& ci) {
  const double gap = ci.gap;
  Contact c;
  c.lin.p = linear::make_params(p.linear, ci);
  c.lin.p.lin_mode = 0; // the bond's normal force is the absolute spring force
  c.tenf = p.cb_tenf;
  c.shearf = p.cb_shearf;
  const double s = bond_gap_scale(ci, p.bond_gap_ratio);
  if (p.bond && gap >= s * p.bond_gap_lo && gap <= s * p.bond_gap_hi)
    c.state = BondState::Bonded;
  return c;
}

void ContactBond::update(Contact& c, const ContactKinematics& k, ContactResult& out,
                         EventSink& events) noexcept {
  if (c.state != BondState::Bonded) {
    Linear::update(c.lin, k, out, events);
    return;
  }
  LinearState& s = c.lin.s;
  const LinearParams& p = c.lin.p;
  // Bonded: the normal spring carries tension too; shear without slip (section 4.4).
  s.Fn = p.kn * (k.gap - p.rgap);
  linear::shear_update(p.ks, p.fric, s.Fn, s.Fss, s.Fst, s.E_slip, s.slip, k, events, false);
  contactbond::point_bond_break(c.tenf, c.shearf, p.fric, s.Fn, s.Fss, s.Fst, c.state, events,
                                [&] { return Linear::energy(c.lin).strain; });
  out = ContactResult{s.Fn, s.Fss, s.Fst, 0, 0, 0};
}

ContactBond::Props ContactBond::read(JsonObject& p, int) {
  Props cb;
  cb.linear = linear::read_props(p, false);
  cb.cb_tenf = p.number("cb_tenf", Range::non_negative(), 0.0, "N");
  cb.cb_shearf = p.number("cb_shearf", Range::non_negative(), 0.0, "N");
  const BondOption b = read_bond_option(p, true);
  cb.bond = b.bond, cb.bond_gap_lo = b.lo, cb.bond_gap_hi = b.hi, cb.bond_gap_ratio = b.ratio;
  return cb;
}

namespace {

class ContactBondCard final : public CardBonding {
public:
  ContactBondCard(JsonObject& top, int dim) {
    // PFC's contact bond on the linear contact: point-bond strengths in force units, the
    // model's own keys (its reader: range and default), drawn per contact.
    std::vector<Distribution> drawn;
    read_card_section<ContactBond>(top, "contactbond", dim, "cb_", {},
                                   {{"cb_tenf", &ContactBondProps::cb_tenf, "N"},
                                    {"cb_shearf", &ContactBondProps::cb_shearf, "N"}},
                                   &drawn);
    tenf_ = drawn[0];
    shearf_ = drawn[1];
  }
  // Draws: the tensile, then the shear strength force.
  CardBond bond(BondDraws& d, const BondSite& site) const override {
    ContactBondProps cb;
    // A point bond made across an open gap would start in tension (its normal force is
    // kn (g - g_r)); the reference gap makes the bonded gap the contact's rest state.
    cb.linear.rgap = std::max(site.gap, 0.0);
    cb.cb_tenf = d.normal(tenf_);
    cb.cb_shearf = d.normal(shearf_);
    return {bonded_on_card_linear(cb, site), ContactBond::card_counts[0]};
  }
  ModelProps props() const override {
    ContactBondProps cb;
    cb.cb_tenf = tenf_.mean;
    cb.cb_shearf = shearf_.mean;
    return cb;
  }
  std::vector<std::pair<std::string, Distribution>> distributions() const override {
    return {{"cb_tenf", tenf_}, {"cb_shearf", shearf_}};
  }

private:
  Distribution tenf_, shearf_;
};

} // namespace

std::unique_ptr<CardBonding> ContactBond::card_bonding(JsonObject& top, int dim) {
  return std::make_unique<ContactBondCard>(top, dim);
}

nlohmann::json ContactBond::state_json(const Contact& cb, int) {
  nlohmann::json j = linear::state_json(cb.lin.p, cb.lin.s);
  j["cb_state"] = cb.state;
  j["cb_tenf"] = cb.tenf;
  j["cb_shearf"] = cb.shearf;
  return j;
}

} // namespace rocklab
