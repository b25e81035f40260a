#include "contact/impact_models.hpp"

#include "contact/linear.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rocklab {

namespace {

// The contact-bond break rule (thesis 4.4), shared by the bonded models: tension at or above
// `tenf` breaks in tension, else shear at or above `shearf` in shear. A broken bond raises its
// event (with the strain energy `stored()` gives before the forces change), records the mode in
// `state`, and leaves no force in tension and the shear cut to the friction limit in
// compression. Returns true if the bond broke.
template <class StoredEnergy>
bool point_bond_break(double tenf, double shearf, double fric, double& Fn, double& Fss, double& Fst,
                      std::uint8_t& state, EventSink& events, StoredEnergy&& stored) noexcept {
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
  state = static_cast<std::uint8_t>(mode);
  if (mode == 1 || Fn > 0) {
    Fn = Fss = Fst = 0;
  } else if (Fs > -fric * Fn) { // the friction limit takes over
    const double scale = -fric * Fn / Fs;
    Fss *= scale;
    Fst *= scale;
  }
  return true;
}

} // namespace

namespace contactbond {

ContactBondContact make(const ContactBondProps& p, int dim, double R1, double R2, bool ball_facet,
                        double gap) {
  ContactBondContact c;
  c.lin.p = linear::make_params(p.linear, dim, R1, R2, ball_facet);
  c.lin.p.lin_mode = 0; // the bond's normal force is the absolute spring force
  c.tenf = p.cb_tenf;
  c.shearf = p.cb_shearf;
  if (p.bond && gap >= p.bond_gap_lo && gap <= p.bond_gap_hi)
    c.state = 3;
  return c;
}

void update(ContactBondContact& c, const ContactKinematics& k, ContactResult& out,
            EventSink& events) noexcept {
  if (c.state != 3) {
    linear::update(c.lin, k, out, events);
    return;
  }
  LinearState& s = c.lin.s;
  const LinearParams& p = c.lin.p;
  // Bonded: the normal spring carries tension too; shear without slip (section 4.4).
  s.Fn = p.kn * (k.gap - p.rgap);
  linear::shear_update(p.ks, p.fric, s.Fn, s.Fss, s.Fst, s.E_slip, s.slip, k, events, false);
  point_bond_break(c.tenf, c.shearf, p.fric, s.Fn, s.Fss, s.Fst, c.state, events,
                   [&] { return linear::energy(c.lin).strain; });
  out = ContactResult{s.Fn, s.Fss, s.Fst, 0, 0, 0};
}

} // namespace contactbond

namespace hysteresis {

HysteresisContact make(const HysteresisProps& p) {
  HysteresisContact c;
  const double d = p.hys_dampn;
  c.k_load = 2 * d * p.hys_knm / (1 + d); // Eq. 21
  c.k_unload = 2 * p.hys_knm / (1 + d);   // Eq. 22
  c.ks = p.hys_ks;
  c.fric = p.hys_fric;
  c.tenf = p.hys_tenf;
  c.shearf = p.hys_shearf;
  if (c.tenf > 0 || c.shearf > 0)
    c.state = 3;
  return c;
}

void update(HysteresisContact& c, const ContactKinematics& k, ContactResult& out,
            EventSink& events) noexcept {
  if (c.state == 3) {
    // Bonded: the same loading/unloading springs, but tension is carried (opening unloads with
    // K_unload, continuing into tension) and the shear does not slip; the bond breaks like a
    // contact bond (thesis 4.4).
    const double dx = -k.d_dn;
    const double F0 = c.Fn;
    const double kk = (dx > 0 && c.Fn <= 0) ? c.k_load : c.k_unload;
    c.Fn = c.Fn - kk * dx;
    c.W_normal += -0.5 * (F0 + c.Fn) * dx;
    c.E_hys = c.W_normal - 0.5 * c.Fn * c.Fn / c.k_unload;
    linear::shear_update(c.ks, c.fric, c.Fn, c.Fss, c.Fst, c.E_slip, c.slip, k, events, false);
    // A zero strength means that part of the bond was not given: it never breaks that way.
    constexpr double never = std::numeric_limits<double>::infinity();
    if (point_bond_break(c.tenf > 0 ? c.tenf : never, c.shearf > 0 ? c.shearf : never, c.fric, c.Fn,
                         c.Fss, c.Fst, c.state, events, [&] { return energy(c).strain; }))
      c.E_hys = c.W_normal - 0.5 * c.Fn * c.Fn / c.k_unload;
    out = ContactResult{c.Fn, c.Fss, c.Fst, 0, 0, 0};
    return;
  }
  if (k.gap > 0) {
    // Separated: no force; a later overlap reloads from wherever it begins (the thesis' drift of
    // the "effective radius" is the model's nature: unloading ends at a residual overlap).
    if (c.slip)
      events.slip_change(false);
    c.Fn = c.Fss = c.Fst = 0;
    c.slip = false;
    out = ContactResult{};
    return;
  }
  // Overlap grows (d_dn < 0): loading stiffness; shrinks: unloading stiffness. No tension.
  const double dx = -k.d_dn;
  const double F0 = c.Fn;
  const double kk = dx > 0 ? c.k_load : c.k_unload;
  c.Fn = std::min(0.0, c.Fn - kk * dx);
  c.W_normal += -0.5 * (F0 + c.Fn) * dx;
  c.E_hys = c.W_normal - 0.5 * c.Fn * c.Fn / c.k_unload;
  linear::shear_update(c.ks, c.fric, c.Fn, c.Fss, c.Fst, c.E_slip, c.slip, k, events);
  out = ContactResult{c.Fn, c.Fss, c.Fst, 0, 0, 0};
}

} // namespace hysteresis

namespace powerplastic {

PowerPlasticContact make(const PowerPlasticProps& p) {
  PowerPlasticContact c;
  c.kn = p.pp_kn;
  c.ks = p.pp_ks;
  c.fric = p.pp_fric;
  c.T = p.pp_T;
  c.b = p.pp_b;
  return c;
}

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

void update(PowerPlasticContact& c, const ContactKinematics& k, ContactResult& out,
            EventSink& events) noexcept {
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

} // namespace rocklab
