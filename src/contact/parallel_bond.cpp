#include "contact/parallel_bond.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace rocklab {

BondSection bond_section(double rmul, int dim, double R1, double R2, bool ball_facet) {
  const double R = rmul * (ball_facet ? R1 : std::min(R1, R2)); // Eq. 5
  const double pi = std::numbers::pi;
  if (dim == 2)
    return {R, 2 * R, 2.0 / 3.0 * R * R * R, 0.0}; // unit thickness
  return {R, pi * R * R, 0.25 * pi * R * R * R * R, 0.5 * pi * R * R * R * R};
}

namespace pbond {

PBondContact make(const PBondProps& p, int dim, double R1, double R2, bool ball_facet, double gap) {
  PBondContact c;
  c.lp = linear::make_params(p.linear, dim, R1, R2, ball_facet);
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
  if (p.bond)
    bond(c, gap, p.bond_gap_lo, p.bond_gap_hi);
  const BondSection b = bond_section(c.p.rmul, dim, R1, R2, ball_facet);
  c.s.R = b.R;
  c.s.A = b.A;
  c.s.I = b.I;
  c.s.J = b.J;
  return c;
}

void bond(PBondContact& c, double gap, double lo, double hi) {
  if (gap < lo || gap > hi)
    return;
  const PBondState old = c.s;
  c.s = PBondState{};
  c.s.R = old.R;
  c.s.A = old.A;
  c.s.I = old.I;
  c.s.J = old.J;
  c.s.state = 3;
}

void unbond(PBondContact& c, double gap, double lo, double hi) {
  if (gap < lo || gap > hi)
    return;
  c.s.state = 0;
}

namespace {
double bond_strain_energy(const PBondContact& c) {
  const PBondState& b = c.s;
  // Eq. 15
  const PBondState& s = c.s;
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

void update(PBondContact& c, const ContactKinematics& k, ContactResult& out,
            EventSink& events) noexcept {
  const bool bonded = c.s.state == 3;
  // The linear component and dashpots, as in the linear model (Eq. 1); dashpots also act while
  // bonded because the contact is then active.
  LinearContact lin{c.lp, c.ls};
  linear::update(lin, k, out, events, /*force_active=*/bonded);
  c.ls = lin.s;
  if (!bonded)
    return;

  PBondState& s = c.s;
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
    s.state = static_cast<std::uint8_t>(mode);
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

ContactStiffness stiffness(const PBondContact& c) {
  ContactStiffness st{c.lp.kn + c.lp.ks, c.lp.ks, 0.0};
  if (c.s.state == 3) { // the bond's translational and rotational stiffnesses
    st.k_tran += (c.p.kn + c.p.ks) * c.s.A;
    st.k_shear += c.p.ks * c.s.A;
    st.k_rot += c.p.kn * c.s.I + c.p.ks * c.s.J;
  }
  return st;
}

ContactEnergy energy(const PBondContact& c) {
  ContactEnergy e = linear::energy(LinearContact{c.lp, c.ls});
  if (c.s.state == 3)
    e.bond_strain = bond_strain_energy(c);
  return e;
}

} // namespace pbond
} // namespace rocklab
