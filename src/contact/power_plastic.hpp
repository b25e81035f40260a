// Elastic-perfectly-plastic power-function model (`powerplastic`, rock-impact thesis section 5,
// Fig. 26, Eq. 23-30): elastic loading capped at a transition force, unloading on a power function
// that returns to the origin; plastic work is what the unloading does not give back. No tension,
// Coulomb slip in shear. SI units.
//
// Stability: the thesis found both impact models blowing up when one step's overlap was large.
// Here the time step is estimated from the largest normal stiffness the contact can ever present
// (the unloading stiffness K_unload, or b k_n for the power branch, whose tangent b F_m / x_m
// never exceeds b k_n because F_m <= k_n x_m), from the step the contact exists, and the engine's
// speed cap keeps the overlap taken in one step small against the margin; so a first-step force
// can never exceed what the stable step allows.
#pragma once

#include "contact/contact_model.hpp"

#include <limits>
#include <string_view>

namespace rocklab {

struct PowerPlasticProps {
  double pp_kn = 0;                                      ///< elastic loading stiffness k_n [N/m]
  double pp_ks = 0;                                      ///< shear stiffness [N/m]
  double pp_fric = 0;                                    ///< friction coefficient [-]
  double pp_T = std::numeric_limits<double>::infinity(); ///< transition force T [N]
  double pp_b = 1; ///< exponent b of the unloading branch F = a x^b, >= 1 [-]
};

struct PowerPlasticContact {
  double kn = 0, ks = 0, fric = 0, T = 0, b = 1;
  double x_max = 0, F_max = 0; ///< turning point: largest overlap and its force [m], [N]
  double x = 0;                ///< overlap at the last update [m]
  double Fn = 0;               ///< normal force, <= 0 compression [N]
  double Fss = 0, Fst = 0;
  double W_normal = 0; ///< work done by the normal force on the overlap so far [J]
  double E_plastic = 0;
  double E_slip = 0;
  bool slip = false;
};

namespace powerplastic {

/// Normal force magnitude for overlap x given the turning point (x_m, F_m): beyond the turning
/// point elastic loading k_n capped at T (perfectly plastic); below it the power branch
/// F = a x^b with a = F_m / x_m^b (Eq. 23), which returns to the origin.
double normal_force(const PowerPlasticContact& c, double x, double& x_m, double& F_m) noexcept;
/// Recoverable energy on the power branch: integral of a x^b from 0 to x = F x / (b + 1)
/// (Eq. 28); plastic = work done - recoverable.
inline double recoverable(const PowerPlasticContact& c) {
  return -c.Fn * c.x / (c.b + 1);
}
/// Closed-form normal restitution of one impact (Eq. 25-30) of mass m at speed v on a rigid
/// obstacle: sqrt(2 / (b + 1)) sqrt((g + 1) / (g + 2)), g = e / p, e = T / k_n; without
/// plastic flow (1/2 m v^2 <= T^2 / (2 k_n)) sqrt(2 / (b + 1)).
double restitution(double m, double v, double kn, double T, double b);

} // namespace powerplastic

/// The elastic-perfectly-plastic power-function model: traits for the registry.
struct PowerPlastic {
  static constexpr std::string_view name = "powerplastic";
  using Props = PowerPlasticProps;
  using Contact = PowerPlasticContact;

  static Contact make(const Props& p, const CreationInfo& ci);
  static void update(Contact& c, const ContactKinematics& k, ContactResult& out,
                     EventSink& events) noexcept;
  static ContactStiffness stiffness(const Contact& c) {
    const double kmax = c.kn * (c.b > 1 ? c.b : 1.0);
    return {kmax + c.ks, c.ks, 0.0};
  }
  static ContactEnergy energy(const Contact& c) {
    ContactEnergy e;
    e.strain = powerplastic::recoverable(c);
    if (c.ks > 0)
      e.strain += 0.5 * (c.Fss * c.Fss + c.Fst * c.Fst) / c.ks;
    e.slip = c.E_slip;
    e.plastic = c.E_plastic;
    return e;
  }
  static bool keeps_alive(const Contact&) { return false; }
  /// Settable properties: pp_fric [-].
  static double* property(Contact& c, std::string_view name) {
    return name == "pp_fric" ? &c.fric : nullptr;
  }
  static Props read(JsonObject& p, int dim);
  static nlohmann::json state_json(const Contact& c, int dim);

  template <class A> static void io(A& a, Props& p) {
    a(p.pp_kn), a(p.pp_ks), a(p.pp_fric), a(p.pp_T), a(p.pp_b);
  }
  template <class A> static void io(A& a, Contact& c) {
    a(c.kn), a(c.ks), a(c.fric), a(c.T), a(c.b), a(c.x_max), a(c.F_max), a(c.x), a(c.Fn), a(c.Fss),
        a(c.Fst), a(c.W_normal), a(c.E_plastic), a(c.E_slip), a(c.slip);
  }
};

} // namespace rocklab
