#include "contact/power_plastic.hpp"

#include "contact/linear.hpp"
#include "io/json_input.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rocklab {

PowerPlastic::Contact PowerPlastic::make(const Props& p, const CreationInfo&) {
  Contact c;
  c.kn = p.pp_kn;
  c.ks = p.pp_ks;
  c.fric = p.pp_fric;
  c.T = p.pp_T;
  c.b = p.pp_b;
  return c;
}

namespace powerplastic {

double normal_force(const PowerPlasticContact& c, double x, double& x_m, double& F_m) noexcept {
  x_m = c.x_max;
  F_m = c.F_max;
  if (x <= 0)
    return 0.0;
  if (x >= x_m) {
    // Loading beyond the turning point: elastic with k_n, perfectly plastic at T (Fig. 26).
    const double F = std::min(c.T, F_m + c.kn * (x - x_m));
    x_m = x;
    F_m = F;
    return F;
  }
  // Unloading (or reloading below the turning point) on F = a x^b, a = F_m / x_m^b (Eq. 23).
  return F_m * std::pow(x / x_m, c.b);
}

} // namespace powerplastic

void PowerPlastic::update(Contact& c, const ContactKinematics& k, ContactResult& out,
                          EventSink& events) noexcept {
  using namespace powerplastic;
  const double x = std::max(-k.gap, 0.0); // overlap
  const double F0 = -c.Fn;
  double x_m, F_m;
  const double F = normal_force(c, x, x_m, F_m);
  c.x_max = x_m;
  c.F_max = F_m;
  // Work on the normal spring (trapezoid over the step), then plastic = work - recoverable.
  c.W_normal += 0.5 * (F0 + F) * (x - c.x);
  c.x = x;
  c.Fn = -F;
  c.E_plastic = c.W_normal - recoverable(c);
  if (k.gap > 0) {
    if (c.slip)
      events.slip_change(false);
    c.Fss = c.Fst = 0;
    c.slip = false;
    out = ContactResult{};
    return;
  }
  linear::shear_update(c.ks, c.fric, c.Fn, c.Fss, c.Fst, c.E_slip, c.slip, k, events);
  out = ContactResult{c.Fn, c.Fss, c.Fst, 0, 0, 0};
}

namespace powerplastic {

double restitution(double m, double v, double kn, double T, double b) {
  const double ek = 0.5 * m * v * v;
  const double e = T / kn; // elastic displacement at the transition force
  if (!(ek > 0.5 * kn * e * e))
    return std::sqrt(2 / (b + 1));
  // Eq. 25: ek = e K (e + 2 p) / 2  ->  p
  const double p = (ek / (0.5 * kn * e) - e) / 2;
  const double g = e / p;
  return std::sqrt(2 / (b + 1)) * std::sqrt((g + 1) / (g + 2)); // Eq. 30
}

} // namespace powerplastic

PowerPlastic::Props PowerPlastic::read(JsonObject& p, int) {
  Props pp;
  pp.pp_kn = p.number("pp_kn", Range::positive(), std::nullopt, "N/m");
  pp.pp_ks = p.number("pp_ks", Range::non_negative(), 0.0, "N/m");
  pp.pp_fric = p.number("pp_fric", Range::non_negative(), 0.0);
  pp.pp_T = p.number("pp_T", Range::positive(), std::numeric_limits<double>::infinity(), "N");
  pp.pp_b = p.number("pp_b", {1, 1000, false, false}, 1.0);
  return pp;
}

nlohmann::json PowerPlastic::state_json(const Contact& pp, int) {
  return {{"pp_force", {{"Fn", pp.Fn}, {"Fss", pp.Fss}, {"Fst", pp.Fst}}},
          {"pp_xmax", pp.x_max},
          {"pp_fmax", pp.F_max},
          {"pp_slip", pp.slip},
          {"E_plastic", pp.E_plastic},
          {"E_slip", pp.E_slip}};
}

} // namespace rocklab
