// Linear parallel bond model (`linearpbond`): the linear component with dashpots acting in
// parallel with a finite-size bond that carries force and moment (linear-parallel-bond-model.md).
#pragma once

#include "contact/linear.hpp"

namespace rocklab {

/// Properties a scene assigns (names as in the seed's Table 2). Stresses in Pa.
struct LinearPBondProps {
  LinearProps linear;   ///< the linear component (kn, ks, fric, dashpots, ...)
  double pb_rmul = 1.0; ///< radius multiplier lambda-bar [-], (0, +inf)
  double pb_kn = 0;     ///< bond normal stiffness [Pa/m]
  double pb_ks = 0;     ///< bond shear stiffness [Pa/m]
  double pb_mcf = 1.0;  ///< moment-contribution factor beta-bar [-], [0, 1]
  double pb_ten = 0;    ///< tensile strength sigma-bar_c [Pa]
  double pb_coh = 0;    ///< cohesion c-bar [Pa]
  double pb_fa = 0;     ///< friction angle phi-bar [deg], [0, 90)
  double pb_emod = 0;   ///< > 0: pb_deformability, kn-bar = E*/L (Eq. 16) [Pa]
  double pb_kratio = 0; ///< kappa-bar* for pb_deformability [-]
  bool bond = true;     ///< apply the bond method when the contact is created
  double bond_gap_lo = -1e300, bond_gap_hi = 0; ///< bond if g_c is in [lo, hi] [m]
  bool bond_gap_ratio = false; ///< lo, hi are fractions of R1 + R2 (specimen version >= 7)
};

struct LinearPBondParams {
  double rmul = 1, kn = 0, ks = 0, mcf = 1, ten = 0, coh = 0, tan_fa = 0;
};

/// Bond state B-bar and the bond's loads.
struct LinearPBondState {
  double Fn = 0;           ///< bond normal force, > 0 tension [N]
  double Fss = 0, Fst = 0; ///< bond shear force [N]
  double Mt = 0;           ///< twisting moment [N m] (3D)
  double Mbs = 0, Mbt = 0; ///< bending moment [N m]
  double gs = 0; ///< bond surface gap, cumulative normal displacement since bonding (Eq. 4) [m]
  double sigma = 0, tau = 0;         ///< peripheral stresses of the last update (Eq. 12) [Pa]
  double R = 0, A = 0, I = 0, J = 0; ///< bond cross-section of the last update (Eq. 5)
  BondState state = BondState::None;
};

struct LinearPBondContact {
  LinearParams lp;
  LinearState ls;
  LinearPBondParams p;
  LinearPBondState s;
};

namespace linearpbond {

/// Bond cross-section (Eq. 5): radius, area, moment of inertia, polar moment.
struct BondSection {
  double R, A, I, J;
};
BondSection bond_section(double rmul, int dim, double R1, double R2, bool ball_facet);

/// The bond method: bond if the contact gap lies in [lo, hi] (force and moment zeroed).
void bond(LinearPBondContact& c, double gap, double lo, double hi);
/// The unbond method: state becomes None; force and moment are left to the next update.
void unbond(LinearPBondContact& c, double gap, double lo, double hi);

} // namespace linearpbond

/// The linear parallel bond model: traits for the registry (contact_model.hpp).
struct LinearPBond {
  static constexpr std::string_view name = "linearpbond";
  using Props = LinearPBondProps;
  using Contact = LinearPBondContact;

  static Contact make(const Props& p, const CreationInfo& ci);
  static void update(Contact& c, const ContactKinematics& k, ContactResult& out,
                     EventSink& events) noexcept;
  static ContactStiffness stiffness(const Contact& c);
  static ContactEnergy energy(const Contact& c);
  static bool keeps_alive(const Contact& c) { return c.s.state == BondState::Bonded; }
  static BondView bond_view(const Contact& c) { return point_bond_view(c.s.state); }
  static void inherit(Props& p, const SurfaceProps& a, const SurfaceProps& b) {
    Linear::inherit(p.linear, a, b);
  }
  /// Settable properties: fric [-] (of the linear component).
  static double* property(Contact& c, std::string_view name) {
    return name == "fric" ? &c.lp.fric : nullptr;
  }
  static constexpr std::string_view methods[] = {"bond", "unbond"};
  static void call(Contact& c, const MethodArgs& m) {
    if (m.name == "bond")
      linearpbond::bond(c, m.gap, m.gap_lo, m.gap_hi);
    else
      linearpbond::unbond(c, m.gap, m.gap_lo, m.gap_hi);
  }
  static Props read(JsonObject& p, int dim);
  static nlohmann::json state_json(const Contact& c, int dim);
  /// A card's "parallelbond" section (card_bonding.hpp): every candidate bonded on the card's
  /// linear part, tension and cohesion drawn per contact.
  static constexpr std::string_view card_section = "parallelbond";
  static constexpr std::string_view card_counts[] = {"bonded"};
  static std::unique_ptr<CardBonding> card_bonding(JsonObject& top, int dim);

  template <class A> static void io(A& a, Props& p) {
    Linear::io(a, p.linear);
    a(p.pb_rmul), a(p.pb_kn), a(p.pb_ks), a(p.pb_mcf), a(p.pb_ten), a(p.pb_coh), a(p.pb_fa),
        a(p.pb_emod), a(p.pb_kratio), a(p.bond), a(p.bond_gap_lo), a(p.bond_gap_hi);
    if (a.version >= 7)
      a(p.bond_gap_ratio);
  }
  template <class A> static void io(A& a, Contact& c) {
    Linear::io(a, c.lp), Linear::io(a, c.ls);
    a(c.p.rmul), a(c.p.kn), a(c.p.ks), a(c.p.mcf), a(c.p.ten), a(c.p.coh), a(c.p.tan_fa);
    a(c.s.Fn), a(c.s.Fss), a(c.s.Fst), a(c.s.Mt), a(c.s.Mbs), a(c.s.Mbt), a(c.s.gs), a(c.s.sigma),
        a(c.s.tau), a(c.s.R), a(c.s.A), a(c.s.I), a(c.s.J), a(c.s.state);
  }
};

} // namespace rocklab
