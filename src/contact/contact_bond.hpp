// Contact-bond model (`contactbond`, rock-impact thesis sections 4.3-4.4): the linear model with a
// point bond that carries tension and suppresses slip until it breaks at force strengths. Its break
// rule is shared with the bonded hysteretic contact. SI units.
#pragma once

#include "contact/contact_model.hpp"
#include "contact/linear.hpp"

#include <cmath>
#include <string_view>

namespace rocklab {

/// The contact bond: the linear model plus a bond at the contact point with normal and shear
/// strengths in force units. While bonded: tension allowed, no slip; breaks in tension when the
/// tensile force reaches cb_tenf (forces then zero), in shear when the shear force reaches
/// cb_shearf (forces kept if compressive and within the friction limit, else the Coulomb limit
/// applies). Unbonded: the linear model.
struct ContactBondProps {
  LinearProps linear;
  double cb_tenf = 0;   ///< normal (tensile) bond strength [N]
  double cb_shearf = 0; ///< shear bond strength [N]
  bool bond = true;     ///< bond when the contact is created (if the gap is within the range)
  double bond_gap_lo = -1e300, bond_gap_hi = 0; ///< [m]
  bool bond_gap_ratio = false; ///< lo, hi are fractions of R1 + R2 (specimen version >= 7)
};

struct ContactBondContact {
  LinearContact lin;
  double tenf = 0, shearf = 0; ///< [N]
  BondState state = BondState::None;
};

namespace contactbond {

/// The contact-bond break rule (thesis 4.4), shared by the bonded models of point contacts:
/// tension at or above `tenf` breaks in tension, else shear at or above `shearf` in shear. A broken
/// bond raises its event (with the strain energy `stored` before the forces change), records the
/// mode in `state`, and leaves no force in tension and the shear cut to the friction limit in
/// compression. Returns true if the bond broke.
template <class StoredEnergy>
bool point_bond_break(double tenf, double shearf, double fric, double& Fn, double& Fss, double& Fst,
                      BondState& state, EventSink& events, StoredEnergy&& stored) noexcept {
  const double Fs = std::sqrt(Fss * Fss + Fst * Fst);
  const int mode = Fn >= tenf ? 1 : (Fs >= shearf ? 2 : 0);
  if (mode == 0)
    return false;
  Event e;
  e.type = EventType::BondBreak;
  e.mode = mode;
  e.strength = mode == 1 ? tenf : shearf;
  e.energy = stored();
  e.size = 0; // a point bond
  events.raise(e);
  state = broken_state(mode);
  if (mode == 1 || Fn > 0) {
    Fn = Fss = Fst = 0;
  } else if (Fs > -fric * Fn) { // the friction limit takes over
    const double scale = -fric * Fn / Fs;
    Fss *= scale;
    Fst *= scale;
  }
  return true;
}

} // namespace contactbond

/// The contact-bond model (PFC `linearcbond`): traits for the registry (contact_model.hpp).
struct ContactBond {
  static constexpr std::string_view name = "contactbond";
  using Props = ContactBondProps;
  using Contact = ContactBondContact;

  static Contact make(const Props& p, const CreationInfo& ci);
  static void update(Contact& c, const ContactKinematics& k, ContactResult& out,
                     EventSink& events) noexcept;
  static ContactStiffness stiffness(const Contact& c) { return Linear::stiffness(c.lin); }
  static ContactEnergy energy(const Contact& c) {
    ContactEnergy e = Linear::energy(c.lin);
    if (c.state == BondState::Bonded) { // the bonded spring's energy is bond energy (3.4)
      e.bond_strain = e.strain;
      e.strain = 0;
    }
    return e;
  }
  static bool keeps_alive(const Contact& c) { return c.state == BondState::Bonded; }
  static BondView bond_view(const Contact& c) { return point_bond_view(c.state); }
  static void inherit(Props& p, const SurfaceProps& a, const SurfaceProps& b) {
    Linear::inherit(p.linear, a, b);
  }
  /// Settable properties: fric [-] (of the linear component).
  static double* property(Contact& c, std::string_view name) {
    return name == "fric" ? &c.lin.p.fric : nullptr;
  }
  static constexpr std::string_view methods[] = {"bond", "unbond"};
  static void call(Contact& c, const MethodArgs& m) {
    if (m.gap >= m.gap_lo && m.gap <= m.gap_hi) // the method's gap filter
      c.state = m.name == "bond" ? BondState::Bonded : BondState::None;
  }
  static Props read(JsonObject& p, int dim);
  /// A card's "contactbond" section (card_bonding.hpp): every candidate point-bonded on the card's
  /// linear part at its gap, the two strength forces drawn per contact.
  static constexpr std::string_view card_section = "contactbond";
  static constexpr std::string_view card_counts[] = {"bonded"};
  static std::unique_ptr<CardBonding> card_bonding(JsonObject& top, int dim);
  static nlohmann::json state_json(const Contact& c, int dim);

  template <class A> static void io(A& a, Props& p) {
    Linear::io(a, p.linear);
    a(p.cb_tenf), a(p.cb_shearf), a(p.bond), a(p.bond_gap_lo), a(p.bond_gap_hi);
    if (a.version >= 7)
      a(p.bond_gap_ratio);
  }
  template <class A> static void io(A& a, Contact& c) {
    Linear::io(a, c.lin);
    a(c.tenf), a(c.shearf), a(c.state);
  }
};

} // namespace rocklab
