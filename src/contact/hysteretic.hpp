// Hysteretic damping model (`hysteretic`, rock-impact thesis section 4.6, Eq. 21-22): loading and
// unloading normal springs of different stiffness dissipate energy in each impact; no tension (but
// for the optional contact-bond, thesis 4.4), Coulomb slip in shear. SI units.
//
// Stability: the thesis found both impact models blowing up when one step's overlap was large.
// Here the time step is estimated from the largest normal stiffness the contact can ever present
// (the unloading stiffness K_unload, or b k_n for the power branch, whose tangent b F_m / x_m
// never exceeds b k_n because F_m <= k_n x_m), from the step the contact exists, and the engine's
// speed cap keeps the overlap taken in one step small against the margin; so a first-step force
// can never exceed what the stable step allows.
#pragma once

#include "contact/contact_bond.hpp"
#include "contact/contact_model.hpp"

#include <string_view>

namespace rocklab {

struct HystereticProps {
  double hys_knm = 0;   ///< mean normal stiffness (K_load + K_unload) / 2 [N/m]
  double hys_dampn = 1; ///< K_load / K_unload, (0, 1] [-]
  double hys_ks = 0;    ///< shear stiffness [N/m]
  double hys_fric = 0;  ///< friction coefficient [-]
  /// Contact-bond option (thesis 4.4 on the hysteretic contact): > 0 bonds the contact when it
  /// is created; while bonded it carries tension and does not slip [N].
  double hys_tenf = 0;
  double hys_shearf = 0;
};

struct HystereticContact {
  double k_load = 0, k_unload = 0, ks = 0, fric = 0; ///< [N/m], [-]
  double Fn = 0; ///< normal force, <= 0 (compression; tension positive convention) [N]
  double Fss = 0, Fst = 0;
  double W_normal = 0; ///< work done on the normal spring so far [J]
  double E_hys = 0;    ///< dissipated by the hysteresis [J]
  double E_slip = 0;
  bool slip = false;
  double tenf = 0, shearf = 0; ///< bond strengths [N]
  BondState state = BondState::None;
};

/// The hysteretic damping model: traits for the registry (contact_model.hpp).
struct Hysteretic {
  static constexpr std::string_view name = "hysteretic";
  using Props = HystereticProps;
  using Contact = HystereticContact;

  /// K_load = 2 d k / (1 + d) (Eq. 21), K_unload = 2 k / (1 + d) (Eq. 22), d = hys_dampn.
  static Contact make(const Props& p, const CreationInfo& ci);
  static void update(Contact& c, const ContactKinematics& k, ContactResult& out,
                     EventSink& events) noexcept;
  static ContactStiffness stiffness(const Contact& c) { return {c.k_unload + c.ks, c.ks, 0.0}; }
  static ContactEnergy energy(const Contact& c) {
    ContactEnergy e;
    if (c.k_unload > 0)
      e.strain = 0.5 * c.Fn * c.Fn / c.k_unload; // what unloading would give back
    if (c.ks > 0)
      e.strain += 0.5 * (c.Fss * c.Fss + c.Fst * c.Fst) / c.ks;
    e.slip = c.E_slip;
    e.dashpot = c.E_hys;
    return e;
  }
  static bool keeps_alive(const Contact& c) { return c.state == BondState::Bonded; }
  static BondView bond_view(const Contact& c) { return point_bond_view(c.state); }
  /// Settable properties: hys_fric [-].
  static double* property(Contact& c, std::string_view name) {
    return name == "hys_fric" ? &c.fric : nullptr;
  }
  static Props read(JsonObject& p, int dim);
  static nlohmann::json state_json(const Contact& c, int dim);

  template <class A> static void io(A& a, Props& p) {
    a(p.hys_knm), a(p.hys_dampn), a(p.hys_ks), a(p.hys_fric), a(p.hys_tenf), a(p.hys_shearf);
  }
  template <class A> static void io(A& a, Contact& c) {
    a(c.k_load), a(c.k_unload), a(c.ks), a(c.fric), a(c.Fn), a(c.Fss), a(c.Fst), a(c.W_normal),
        a(c.E_hys), a(c.E_slip), a(c.slip), a(c.tenf), a(c.shearf), a(c.state);
  }
};

} // namespace rocklab
