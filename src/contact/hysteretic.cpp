#include "contact/hysteretic.hpp"

#include "contact/linear.hpp"
#include "io/json_input.hpp"

#include <algorithm>
#include <limits>

namespace rocklab {

using contactbond::point_bond_break;

Hysteretic::Contact Hysteretic::make(const Props& p, const CreationInfo&) {
  Contact c;
  const double d = p.hys_dampn;
  c.k_load = 2 * d * p.hys_knm / (1 + d); // Eq. 21
  c.k_unload = 2 * p.hys_knm / (1 + d);   // Eq. 22
  c.ks = p.hys_ks;
  c.fric = p.hys_fric;
  c.tenf = p.hys_tenf;
  c.shearf = p.hys_shearf;
  if (c.tenf > 0 || c.shearf > 0)
    c.state = BondState::Bonded;
  return c;
}

void Hysteretic::update(Contact& c, const ContactKinematics& k, ContactResult& out,
                        EventSink& events) noexcept {
  if (c.state == BondState::Bonded) {
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

Hysteretic::Props Hysteretic::read(JsonObject& p, int) {
  Props h;
  h.hys_knm = p.number("hys_knm", Range::positive(), std::nullopt, "N/m");
  h.hys_dampn = p.number("hys_dampn", {0, 1, true, false}, 1.0);
  h.hys_ks = p.number("hys_ks", Range::non_negative(), 0.0, "N/m");
  h.hys_fric = p.number("hys_fric", Range::non_negative(), 0.0);
  h.hys_tenf = p.number("hys_tenf", Range::non_negative(), 0.0, "N");
  h.hys_shearf = p.number("hys_shearf", Range::non_negative(), 0.0, "N");
  return h;
}

nlohmann::json Hysteretic::state_json(const Contact& h, int) {
  return {{"hys_kload", h.k_load},
          {"hys_kunload", h.k_unload},
          {"hys_force", {{"Fn", h.Fn}, {"Fss", h.Fss}, {"Fst", h.Fst}}},
          {"hys_slip", h.slip},
          {"E_hysteresis", h.E_hys},
          {"E_slip", h.E_slip}};
}

} // namespace rocklab
