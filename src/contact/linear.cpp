#include "contact/linear.hpp"

#include "io/json_input.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace rocklab {
namespace linear {

LinearParams make_params(const LinearProps& p, const CreationInfo& ci) {
  const int dim = ci.dim;
  const double R1 = ci.R1, R2 = ci.R2;
  const bool ball_facet = ci.ball_facet;
  LinearParams q;
  q.kn = p.kn;
  q.ks = p.ks;
  if (p.emod > 0) {
    const double r = ball_facet ? R1 : std::min(R1, R2);
    const double area = p.user_area > 0 ? p.user_area : deformability_area(dim, r);
    const double L = ball_facet ? R1 : R1 + R2;
    q.kn = area * p.emod / L;
    q.ks = p.kratio > 0 ? q.kn / p.kratio : 0.0;
  }
  q.fric = p.fric;
  q.rgap = p.rgap;
  q.dp_nratio = p.dp_nratio;
  q.dp_sratio = p.dp_sratio;
  q.lin_mode = static_cast<std::uint8_t>(p.lin_mode);
  q.dp_mode = static_cast<std::uint8_t>(p.dp_mode);
  return q;
}

void update_linear_part(const LinearParams& p, LinearState& s, const ContactKinematics& k,
                        EventSink& events, bool slip_allowed) noexcept {
  const double gs = k.gap - p.rgap; // surface gap of the linear interface
  // Normal force, tension positive; the linear interface carries no tension.
  if (p.lin_mode == 0)
    s.Fn = p.kn * gs;
  else
    s.Fn = s.Fn + p.kn * k.d_dn;
  s.Fn = std::min(s.Fn, 0.0);

  shear_update(p.ks, p.fric, s.Fn, s.Fss, s.Fst, s.E_slip, s.slip, k, events, slip_allowed);
}

void shear_update(double ks, double fric, double Fn, double& Fss, double& Fst, double& E_slip,
                  bool& slip, const ContactKinematics& k, EventSink& events,
                  bool slip_allowed) noexcept {
  // Shear force: trial increment, then the Coulomb limit F_s^mu = -mu Fn.
  const double F0ss = Fss, F0st = Fst;
  double tss = F0ss - ks * k.d_dss;
  double tst = F0st - ks * k.d_dst;
  const double limit = -fric * Fn;
  const double trial = std::sqrt(tss * tss + tst * tst);
  const bool slipping = slip_allowed && trial > limit;
  if (slipping) {
    const double scale = trial > 0 ? limit / trial : 0.0;
    tss *= scale;
    tst *= scale;
  }
  Fss = tss;
  Fst = tst;
  // Slip energy: the part of the shear increment not taken up elastically does friction work
  // (zero by definition while sticking; skipping it then avoids round-off residue).
  if (slipping && ks > 0) {
    const double dk_ss = -(Fss - F0ss) / ks, dk_st = -(Fst - F0st) / ks;
    const double dmu_ss = k.d_dss - dk_ss, dmu_st = k.d_dst - dk_st;
    E_slip -= 0.5 * ((F0ss + Fss) * dmu_ss + (F0st + Fst) * dmu_st);
  }
  if (slipping != slip) {
    events.slip_change(slipping);
    slip = slipping;
  }
}

LinearProps read_props(JsonObject& p, bool kn_required) {
  LinearProps lp;
  const StiffnessPair k = read_stiffness_pair(p, "", "N/m", kn_required);
  lp.kn = k.kn, lp.ks = k.ks, lp.emod = k.emod, lp.kratio = k.kratio;
  if (k.deformability)
    lp.user_area = p.number("user_area", Range::non_negative(), 0.0, "m^2");
  lp.fric = p.number("fric", Range::non_negative(), 0.0);
  lp.rgap = p.number("rgap", Range::any(), 0.0, "m");
  lp.lin_mode = static_cast<int>(p.integer("lin_mode", 0, 1, 0));
  lp.dp_nratio = p.number("dp_nratio", Range::closed(0, 1), 0.0);
  lp.dp_sratio = p.number("dp_sratio", Range::closed(0, 1), 0.0);
  lp.dp_mode = static_cast<int>(p.integer("dp_mode", 0, 3, 0));
  return lp;
}

nlohmann::json state_json(const LinearParams& p, const LinearState& s) {
  return nlohmann::json{{"kn", p.kn},
                        {"ks", p.ks},
                        {"fric", p.fric},
                        {"lin_slip", s.slip},
                        {"lin_force", {{"Fn", s.Fn}, {"Fss", s.Fss}, {"Fst", s.Fst}}},
                        {"E_slip", s.E_slip},
                        {"E_dashpot", s.E_dashpot}};
}

} // namespace linear

nlohmann::json Linear::state_json(const Contact& c, int) {
  return linear::state_json(c.p, c.s);
}

void Linear::update(Contact& c, const ContactKinematics& k, ContactResult& out, EventSink& events,
                    bool force_active) noexcept {
  using namespace linear;
  const LinearParams& p = c.p;
  LinearState& s = c.s;
  const double gs = k.gap - p.rgap;
  const bool open = gs > 0.0;
  if (open && s.slip)
    events.slip_change(false);
  if (open) {
    // The linear interface is open: no linear force. The contact stays active only when a
    // bonded model says so, and then only its dashpots act.
    s = LinearState{.E_slip = s.E_slip, .E_dashpot = s.E_dashpot};
    if (!force_active) {
      out = ContactResult{};
      return;
    }
  } else {
    update_linear_part(p, s, k, events);
  }

  // Dashpots: F_n^d = 2 beta_n sqrt(m_c kn) v_n (opposes opening), shear opposes sliding.
  double Fdn = 0, Fdss = 0, Fdst = 0;
  if (k.dt > 0 && (p.dp_nratio > 0 || p.dp_sratio > 0)) {
    const double cn = 2.0 * p.dp_nratio * std::sqrt(k.mass_eff * p.kn);
    const double cs = 2.0 * p.dp_sratio * std::sqrt(k.mass_eff * p.ks);
    Fdn = cn * k.d_dn / k.dt;
    Fdss = -cs * k.d_dss / k.dt;
    Fdst = -cs * k.d_dst / k.dt;
    const bool no_tension = p.dp_mode == 1 || p.dp_mode == 3;
    const bool slip_cut = p.dp_mode == 2 || p.dp_mode == 3;
    if (no_tension && s.Fn + Fdn > 0)
      Fdn = -s.Fn;
    if (slip_cut && s.slip)
      Fdss = Fdst = 0;
    // Dissipation: minus the work of the dashpot force on the relative displacement.
    s.E_dashpot -= -Fdn * k.d_dn + Fdss * k.d_dss + Fdst * k.d_dst;
  }
  out = ContactResult{s.Fn + Fdn, s.Fss + Fdss, s.Fst + Fdst, 0, 0, 0};
}

} // namespace rocklab
