#include "contact/linear_pbond.hpp"

#include "contact/card_bonding.hpp"
#include "io/json_input.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace rocklab {
namespace linearpbond {

BondSection bond_section(double rmul, int dim, double R1, double R2, bool ball_facet) {
  const double R = rmul * (ball_facet ? R1 : std::min(R1, R2)); // Eq. 5
  const double pi = std::numbers::pi;
  if (dim == 2)
    return {R, 2 * R, 2.0 / 3.0 * R * R * R, 0.0}; // unit thickness
  return {R, pi * R * R, 0.25 * pi * R * R * R * R, 0.5 * pi * R * R * R * R};
}

void bond(LinearPBondContact& c, double gap, double lo, double hi) {
  if (gap < lo || gap > hi)
    return;
  const LinearPBondState old = c.s;
  c.s = LinearPBondState{};
  c.s.R = old.R;
  c.s.A = old.A;
  c.s.I = old.I;
  c.s.J = old.J;
  c.s.state = BondState::Bonded;
}

void unbond(LinearPBondContact& c, double gap, double lo, double hi) {
  if (gap < lo || gap > hi)
    return;
  c.s.state = BondState::None;
}

} // namespace linearpbond

using namespace linearpbond;

LinearPBond::Contact LinearPBond::make(const Props& p, const CreationInfo& ci) {
  const int dim = ci.dim;
  const double R1 = ci.R1, R2 = ci.R2;
  const bool ball_facet = ci.ball_facet;
  Contact c;
  c.lp = linear::make_params(p.linear, ci);
  c.p.rmul = p.pb_rmul;
  c.p.kn = p.pb_kn;
  c.p.ks = p.pb_ks;
  if (p.pb_emod > 0) { // pb_deformability, Eq. 16
    const double L = ball_facet ? R1 : R1 + R2;
    c.p.kn = p.pb_emod / L;
    c.p.ks = p.pb_kratio > 0 ? c.p.kn / p.pb_kratio : 0.0;
  }
  c.p.mcf = p.pb_mcf;
  c.p.ten = p.pb_ten;
  c.p.coh = p.pb_coh;
  c.p.tan_fa = std::tan(p.pb_fa * std::numbers::pi / 180.0);
  if (p.bond) {
    const double s = bond_gap_scale(ci, p.bond_gap_ratio);
    bond(c, ci.gap, s * p.bond_gap_lo, s * p.bond_gap_hi);
  }
  const BondSection b = bond_section(c.p.rmul, dim, R1, R2, ball_facet);
  c.s.R = b.R;
  c.s.A = b.A;
  c.s.I = b.I;
  c.s.J = b.J;
  return c;
}

namespace {
double bond_strain_energy(const LinearPBondContact& c) {
  const LinearPBondState& b = c.s;
  // Eq. 15
  const LinearPBondState& s = c.s;
  if (b.A <= 0)
    return 0;
  double e = 0;
  if (c.p.kn > 0)
    e += s.Fn * s.Fn / (c.p.kn * b.A) + (s.Mbs * s.Mbs + s.Mbt * s.Mbt) / (c.p.kn * b.I);
  if (c.p.ks > 0) {
    e += (s.Fss * s.Fss + s.Fst * s.Fst) / (c.p.ks * b.A);
    if (b.J > 0)
      e += s.Mt * s.Mt / (c.p.ks * b.J);
  }
  return 0.5 * e;
}
} // namespace

void LinearPBond::update(Contact& c, const ContactKinematics& k, ContactResult& out,
                         EventSink& events) noexcept {
  const bool bonded = c.s.state == BondState::Bonded;
  // The linear component and dashpots, as in the linear model (Eq. 1); dashpots also act while
  // bonded because the contact is then active.
  LinearContact lin{c.lp, c.ls};
  Linear::update(lin, k, out, events, /*force_active=*/bonded);
  c.ls = lin.s;
  if (!bonded)
    return;

  LinearPBondState& s = c.s;
  const BondSection b = bond_section(c.p.rmul, k.dim, k.R1, k.R2, k.ball_facet);
  s.R = b.R;
  s.A = b.A;
  s.I = b.I;
  s.J = b.J;
  s.gs += k.d_dn;                  // Eq. 4
  s.Fn += c.p.kn * b.A * k.d_dn;   // Eq. 6
  s.Fss -= c.p.ks * b.A * k.d_dss; // Eq. 7
  s.Fst -= c.p.ks * b.A * k.d_dst;
  s.Mt = k.dim == 2 ? 0.0 : s.Mt - c.p.ks * b.J * k.d_tt; // Eq. 8
  s.Mbs -= c.p.kn * b.I * k.d_tbs;                        // Eq. 10
  s.Mbt -= c.p.kn * b.I * k.d_tbt;

  // Eq. 12: peripheral stresses with the moment-contribution factor.
  const double Mb = std::sqrt(s.Mbs * s.Mbs + s.Mbt * s.Mbt);
  const double Fs = std::sqrt(s.Fss * s.Fss + s.Fst * s.Fst);
  s.sigma = s.Fn / b.A + c.p.mcf * Mb * b.R / b.I;
  s.tau = Fs / b.A + (k.dim == 2 ? 0.0 : c.p.mcf * std::abs(s.Mt) * b.R / b.J);

  int mode = 0;
  double strength = 0;
  if (s.sigma > c.p.ten) { // Eq. 13
    mode = 1;
    strength = c.p.ten;
  } else {
    const double tau_c = c.p.coh - (s.Fn / b.A) * c.p.tan_fa;
    if (s.tau > tau_c) { // Eq. 14
      mode = 2;
      strength = tau_c;
    }
  }
  if (mode != 0) {
    Event e;
    e.type = EventType::BondBreak;
    e.mode = mode;
    e.strength = strength;
    e.energy = bond_strain_energy(c);
    e.size = 2 * b.R;
    events.raise(e);
    s.Fn = s.Fss = s.Fst = s.Mt = s.Mbs = s.Mbt = 0;
    s.state = broken_state(mode);
    return;
  }
  // Eq. 1-3: the bond force and moment act in parallel with the linear force.
  out.Fn += s.Fn;
  out.Fss += s.Fss;
  out.Fst += s.Fst;
  out.Mt += s.Mt;
  out.Mbs += s.Mbs;
  out.Mbt += s.Mbt;
}

ContactStiffness LinearPBond::stiffness(const Contact& c) {
  ContactStiffness st{c.lp.kn + c.lp.ks, c.lp.ks, 0.0};
  if (c.s.state == BondState::Bonded) { // the bond's translational and rotational stiffnesses
    st.k_tran += (c.p.kn + c.p.ks) * c.s.A;
    st.k_shear += c.p.ks * c.s.A;
    st.k_rot += c.p.kn * c.s.I + c.p.ks * c.s.J;
  }
  return st;
}

ContactEnergy LinearPBond::energy(const Contact& c) {
  ContactEnergy e = Linear::energy(LinearContact{c.lp, c.ls});
  if (c.s.state == BondState::Bonded)
    e.bond_strain = bond_strain_energy(c);
  return e;
}

LinearPBond::Props LinearPBond::read(JsonObject& p, int) {
  Props pb;
  pb.linear = linear::read_props(p, false);
  pb.pb_rmul = p.number("pb_rmul", Range::at_least(kMinRadiusMultiplier), 1.0);
  const StiffnessPair k = read_stiffness_pair(p, "pb_", "Pa/m", false);
  pb.pb_kn = k.kn, pb.pb_ks = k.ks, pb.pb_emod = k.emod, pb.pb_kratio = k.kratio;
  pb.pb_mcf = p.number("pb_mcf", Range::closed(0, 1), 1.0);
  pb.pb_ten = p.number("pb_ten", Range::non_negative(), 0.0, "Pa");
  pb.pb_coh = p.number("pb_coh", Range::non_negative(), 0.0, "Pa");
  pb.pb_fa = p.number("pb_fa", Range::half_open(0, 90), 0.0, "deg");
  const BondOption b = read_bond_option(p, true);
  pb.bond = b.bond, pb.bond_gap_lo = b.lo, pb.bond_gap_hi = b.hi, pb.bond_gap_ratio = b.ratio;
  return pb;
}

namespace {

class ParallelBondCard final : public CardBonding {
public:
  ParallelBondCard(JsonObject& top, int dim) {
    std::vector<Distribution> drawn;
    pb_ = read_card_section<LinearPBond>(
        top, "parallelbond", dim, "pb_", {},
        {{"pb_ten", &LinearPBondProps::pb_ten, "Pa"}, {"pb_coh", &LinearPBondProps::pb_coh, "Pa"}},
        &drawn);
    ten_ = drawn[0];
    coh_ = drawn[1];
    JsonObject p = top.object("parallelbond");
    if (!(pb_.pb_emod > 0 || pb_.pb_kn > 0))
      p.fail("pb_emod", "missing: a card's parallel bonds need a stiffness (pb_emod with "
                        "pb_kratio, or pb_kn with pb_ks)");
  }
  // Draws: tension, then cohesion.
  CardBond bond(BondDraws& d, const BondSite& site) const override {
    LinearPBondProps pb = pb_;
    pb.pb_ten = d.normal(ten_);
    pb.pb_coh = d.normal(coh_);
    return {bonded_on_card_linear(pb, site), LinearPBond::card_counts[0]};
  }
  ModelProps props() const override {
    LinearPBondProps pb = pb_;
    pb.pb_ten = ten_.mean;
    pb.pb_coh = coh_.mean;
    return pb;
  }
  std::vector<std::pair<std::string, Distribution>> distributions() const override {
    return {{"pb_ten", ten_}, {"pb_coh", coh_}};
  }

private:
  LinearPBondProps pb_;
  Distribution ten_, coh_;
};

} // namespace

std::unique_ptr<CardBonding> LinearPBond::card_bonding(JsonObject& top, int dim) {
  return std::make_unique<ParallelBondCard>(top, dim);
}

nlohmann::json LinearPBond::state_json(const Contact& c, int) {
  nlohmann::json j = linear::state_json(c.lp, c.ls);
  j["pb_state"] = c.s.state;
  j["pb_radius"] = c.s.R;
  j["pb_kn"] = c.p.kn;
  j["pb_ks"] = c.p.ks;
  j["pb_gap"] = c.s.gs;
  j["pb_sigma"] = c.s.sigma;
  j["pb_tau"] = c.s.tau;
  j["pb_force"] = {{"Fn", c.s.Fn}, {"Fss", c.s.Fss}, {"Fst", c.s.Fst}};
  j["pb_moment"] = {{"Mt", c.s.Mt}, {"Mbs", c.s.Mbs}, {"Mbt", c.s.Mbt}};
  return j;
}

} // namespace rocklab
