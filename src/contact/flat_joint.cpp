#include "contact/flat_joint.hpp"

#include "io/json_input.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>
#include <stdexcept>
#include <string>

namespace rocklab {

namespace {
constexpr double kPi = std::numbers::pi;
} // namespace

namespace {

double element_strain_energy(const FlatJointContact& c, const FlatJointElement& el, std::size_t i,
                             double A, int dim) {
  double e = 0;
  if (c.kn > 0)
    e += el.Fn * el.Fn / (c.kn * A);
  if (c.ks > 0)
    e += (el.Fss * el.Fss + el.Fst * el.Fst) / (c.ks * A);
  if (dim == 2) { // Eq. 37, exact in 2D
    const double rbar = c.R / c.geo->Nr;
    if (c.kn > 0)
      e += el.Mbs * el.Mbs / (c.kn * 2.0 / 3.0 * rbar * rbar * rbar);
  } else if (!c.exact) {
    // Eq. 37 in 3D: the element taken as a disk of equal area.
    const double re2 = A / kPi;
    if (c.kn > 0)
      e += (el.Mbs * el.Mbs + el.Mbt * el.Mbt) / (c.kn * 0.25 * kPi * re2 * re2);
    if (c.ks > 0)
      e += el.Mt * el.Mt / (c.ks * 0.5 * kPi * re2 * re2);
  } else {
    // Exact elements carry the moments of the sector's true stress field, so their energy
    // uses the sector's own centroidal second moments: E = m^T I^-1 m / (2 kn), m = (Mt, -Ms).
    const FlatJointGeometry& g = *c.geo;
    const double R4 = std::pow(c.R, 4), se = g.s[i] * c.R, te = g.t[i] * c.R;
    const double Iss = g.Ixx[i] * R4 - A * se * se, Ist = g.Ixy[i] * R4 - A * se * te,
                 Itt = g.Iyy[i] * R4 - A * te * te;
    const double det = Iss * Itt - Ist * Ist;
    const double m1 = el.Mbt, m2 = -el.Mbs;
    if (c.kn > 0 && det > 0)
      e += (Itt * m1 * m1 - 2 * Ist * m1 * m2 + Iss * m2 * m2) / det / c.kn;
    const double Jc = g.Jp[i] * R4 - A * (se * se + te * te);
    if (c.ks > 0 && Jc > 0)
      e += el.Mt * el.Mt / (c.ks * Jc);
  }
  return 0.5 * e;
}

} // namespace

namespace flatjoint {

void element_2d(double kn, double rbar, double ga, double gb, bool bonded, double& Fn, double& Mb) {
  // Eq. 46-49 (t = 1); cases in the memo's order.
  if (ga * gb < 0) {
    if (bonded) {
      Fn = kn * rbar * (ga + gb);
      Mb = kn * rbar * rbar * (ga - gb) / 3;
    } else if (ga < 0) {
      Fn = kn * rbar * ga * ga / (ga - gb);
      Mb = kn * rbar * rbar * ga * ga * (ga - 3 * gb) / (3 * (gb - ga) * (gb - ga));
    } else {
      Fn = kn * rbar * gb * gb / (gb - ga);
      const double d = gb - ga;
      Mb = kn * rbar * rbar * (-d * d * d - ga * ga * (ga - 3 * gb)) / (3 * d * d);
    }
  } else if (ga >= 0 && gb >= 0) {
    Fn = bonded ? kn * rbar * (ga + gb) : 0.0;
    Mb = bonded ? kn * rbar * rbar * (ga - gb) / 3 : 0.0;
  } else {
    Fn = kn * rbar * (ga + gb);
    Mb = kn * rbar * rbar * (ga - gb) / 3;
  }
}

} // namespace flatjoint

using flatjoint::bond;

FlatJoint::Contact FlatJoint::make(const Props& p, const CreationInfo& ci, Pool& pool) {
  const int dim = ci.dim;
  const double R1 = ci.R1, R2 = ci.R2;
  const bool ball_facet = ci.ball_facet;
  std::vector<FlatJointElement>& elements = pool.all;
  Contact c;
  c.geo = &flat_joint_geometry(dim, p.fj_Nr, p.fj_Nal);
  c.kn = p.fj_kn;
  c.ks = p.fj_ks;
  if (p.fj_emod > 0) { // deformability, Eq. 40
    const double L = ball_facet ? R1 : R1 + R2;
    c.kn = p.fj_emod / L;
    c.ks = p.fj_kratio > 0 ? c.kn / p.fj_kratio : 0.0;
  }
  c.fric = p.fj_fric;
  c.ten = p.fj_ten;
  c.coh = p.fj_coh;
  c.tan_fa = std::tan(p.fj_fa * kPi / 180.0);
  c.rmul = p.fj_rmul;
  c.gap0 = p.fj_gap0;
  c.exact = p.fj_exact && dim == 3;
  c.R = c.rmul * (ball_facet ? R1 : std::min(R1, R2)); // Eq. 30
  c.gs = c.gap0;                                       // Eq. 31
  c.elem = static_cast<std::uint32_t>(elements.size());
  c.n_elem = static_cast<std::uint16_t>(c.geo->A.size());
  elements.resize(elements.size() + c.n_elem); // Eq. 29: all element forces zero
  std::span<FlatJointElement> e(elements.data() + c.elem, c.n_elem);
  const double s = bond_gap_scale(ci, p.bond_gap_ratio);
  const bool bonded = p.bond && ci.gap >= s * p.bond_gap_lo && ci.gap <= s * p.bond_gap_hi;
  if (bonded)
    bond(c, e);
  c.mtype = c.gap0 > 0 ? 2 : (bonded ? 1 : 3);
  return c;
}

namespace flatjoint {

void bond(FlatJointContact& c, std::span<FlatJointElement> e, std::size_t first) {
  // Only elements with a zero gap over their whole surface can be bonded.
  const double tb = std::hypot(c.tbs, c.tbt);
  for (std::size_t i = 0; i < e.size(); ++i) {
    const double s = c.geo->s[first + i] * c.R, t = c.geo->t[first + i] * c.R;
    if (gap_at(c, s, t) == 0 && tb == 0)
      e[i].B = BondState::Bonded;
  }
}

void unbond(FlatJointContact&, std::span<FlatJointElement> e) {
  for (auto& el : e)
    el.B = BondState::None;
}

} // namespace flatjoint

namespace {

// One element's part of an update (memo section 1.5, steps 1-3): the step's interface motion and
// the element's place in it.
struct ElementStep {
  const FlatJointContact& c;
  const FlatJointGeometry& geo;
  const ContactKinematics& k;
  EventSink& events;
  double gs0, tbs0, tbt0; ///< interface gap and bend rotations at the start of the step
  std::size_t i = 0;      ///< element index
  double A = 0;           ///< element area [m^2] (2D: per unit thickness)
  double se = 0, te = 0;  ///< element centroid in the contact plane [m]
  double g0 = 0, g1 = 0;  ///< centroid gap at the start and end of the step [m]

  // Inlined into the element loop (as the one function they were split from was): called per
  // element per contact per step, out-of-line calls here cost 5 % of the flat-joint cycle.
  [[gnu::always_inline]] inline void run(FlatJointElement& el);
  [[gnu::always_inline]] inline void normal(FlatJointElement& el, bool bonded) const;
  [[gnu::always_inline]] inline void shear(FlatJointElement& el, bool bonded, double sigma) const;
  void end_slip(FlatJointElement& el) const {
    if (el.slip) {
      el.slip = false;
      events.slip_change(false, static_cast<std::int32_t>(i) + 1);
    }
  }
  void raise_break(int mode, double strength, double energy) const {
    Event ev;
    ev.type = EventType::BondBreak;
    ev.mode = mode;
    ev.element = static_cast<int>(i) + 1;
    ev.position = Vec3(0, se, te); // element centroid, contact-plane offsets
    ev.size = k.dim == 2 ? 2 * (c.R / geo.Nr) : 2 * std::sqrt(A / kPi);
    ev.gap = g1;
    ev.strength = strength;
    ev.energy = energy;
    events.raise(ev);
  }
};

// Step 1 and 3: element normal force and bending moment (Eq. 32, 35).
void ElementStep::normal(FlatJointElement& el, bool bonded) const {
  const double R = c.R;
  if (k.dim == 2) {
    // Ends of element i: t = te + rbar (gamma_a) and t = te - rbar (gamma_b), Eq. 44.
    const double rbar = R / geo.Nr; // 2D element half-length
    const double ga = c.gs + (te + rbar) * c.tbs, gb = c.gs + (te - rbar) * c.tbs;
    double Mb_k;
    flatjoint::element_2d(c.kn, rbar, ga, gb, bonded, el.Fn, Mb_k);
    el.Mbs = -Mb_k; // s = -k in 2D
    el.Mbt = 0;
  } else if (!c.exact) {
    el.Fn = (!bonded && g1 >= 0) ? 0.0 : c.kn * g1 * A; // Eq. 50
    el.Mbs = el.Mbt = 0;
  } else {
    // Exact integral of the linear normal stress over the sector (or its compressed part).
    const double bs = -c.tbt, bt = c.tbs; // g = gs + s bs + t bt
    flatjoint::Moments m;
    if (bonded) {
      const double R2 = R * R, R3 = R2 * R, R4 = R3 * R;
      m = {geo.A[i] * R2,   geo.s[i] * geo.A[i] * R3, geo.t[i] * geo.A[i] * R3,
           geo.Ixx[i] * R4, geo.Ixy[i] * R4,          geo.Iyy[i] * R4};
    } else {
      m = flatjoint::clipped_moments(geo.r1[i] * R, geo.r2[i] * R, geo.a1[i], geo.a2[i], c.gs, bs,
                                     bt);
    }
    el.Fn = c.kn * (c.gs * m[0] + bs * m[1] + bt * m[2]);
    const double Ms = -c.kn * (c.gs * m[2] + bs * m[4] + bt * m[5]); // -int t sigma
    const double Mt = c.kn * (c.gs * m[1] + bs * m[3] + bt * m[4]);  //  int s sigma
    el.Mbs = Ms + te * el.Fn;                                        // about the element centroid
    el.Mbt = Mt - se * el.Fn;
  }
}

// Step 2: shear (Eq. 12, 33-34), on the effective part of the centroid increment; Coulomb slip
// when unbonded, the shear strength when bonded.
void ElementStep::shear(FlatJointElement& el, bool bonded, double sigma) const {
  const double R = c.R;
  const double alpha = (!bonded && g0 > 0 && g1 < 0) ? g1 / (g1 - g0) : 1.0;
  const double dss = alpha * (k.d_dss - k.d_tt * te);
  const double dst = alpha * (k.d_dst + k.d_tt * se);
  double Fss = el.Fss - c.ks * A * dss;
  double Fst = el.Fst - c.ks * A * dst;
  const double tau = std::sqrt(Fss * Fss + Fst * Fst) / A;
  if (!bonded) {
    const double tau_c = -c.fric * sigma;
    const bool slipping = tau > tau_c;
    if (slipping) {
      const double scale = tau > 0 ? tau_c / tau : 0.0;
      Fss *= scale;
      Fst *= scale;
      // Eq. 39 with the slip part of the increment only (the part not taken up elastically,
      // -(F - F0) / (ks A)); in steady sliding the two agree, and in the step where slip
      // starts this keeps the slip energy equal to the friction work.
      const double ess = dss + (Fss - el.Fss) / (c.ks * A);
      const double est = dst + (Fst - el.Fst) / (c.ks * A);
      el.E_slip += tau_c * A * std::sqrt(ess * ess + est * est);
      el.Mt = 0;
    } else if (c.exact) {
      el.Mt -= c.ks * alpha * k.d_tt * (geo.Jp[i] * R * R * R * R - A * (se * se + te * te));
    }
    el.Fss = Fss;
    el.Fst = Fst;
    if (slipping != el.slip) {
      el.slip = slipping;
      events.slip_change(slipping, static_cast<std::int32_t>(i) + 1);
    }
    return;
  }
  const double tau_c = c.coh - sigma * c.tan_fa;
  if (tau > tau_c) { // shear break
    // Released is what the element no longer stores: under compression the unbonded element
    // keeps its normal force (and its strain energy), so the whole energy before the break would
    // count that part twice (seen: a Brazilian disk crushed at a platen, ledger open by 5 %).
    const double before = element_strain_energy(c, el, i, A, k.dim);
    el.B = BondState::Shear;
    el.Fss = el.Fst = el.Mt = 0;
    normal(el, false); // re-evaluate as unbonded
    raise_break(2, tau_c, before - element_strain_energy(c, el, i, A, k.dim));
  } else {
    el.Fss = Fss;
    el.Fst = Fst;
    if (c.exact) // twist shear varies linearly over the element: its own twisting moment
      el.Mt -= c.ks * k.d_tt * (geo.Jp[i] * R * R * R * R - A * (se * se + te * te));
  }
}

void ElementStep::run(FlatJointElement& el) {
  const double R = c.R;
  A = geo.A[i] * (k.dim == 2 ? R : R * R);
  se = geo.s[i] * R;
  te = geo.t[i] * R;
  g0 = gs0 + te * tbs0 - se * tbt0; // centroid gap, start of step
  g1 = c.gs + te * c.tbs - se * c.tbt;
  const bool bonded = el.B == BondState::Bonded;
  normal(el, bonded);
  const double sigma = el.Fn / A; // Eq. 27
  if (bonded && sigma > c.ten) {  // tensile break
    const double energy = element_strain_energy(c, el, i, A, k.dim);
    el.B = BondState::Tension;
    el.Fn = el.Fss = el.Fst = el.Mt = 0;
    raise_break(1, c.ten, energy);
    // Step 3 with the now unbonded element (Fn stays zero as the memo prescribes).
    normal(el, false);
    el.Fn = 0;
    return;
  }
  if (!bonded && sigma >= 0) { // open: no shear
    el.Fss = el.Fst = el.Mt = 0;
    end_slip(el);
    return;
  }
  shear(el, bonded, sigma);
}

// The smallest gap over the interface, gs - R |tb|, is not negative (section 1.6). Decided by
// squares where they settle it with a margin far above round-off, so that the costly libm hypot
// (7 % of a flat-jointed UCS cycle, on every unbonded contact) runs only near equality, where it
// gives the same answer as before to the bit.
bool open_everywhere(double gs, double R, double tbs, double tbt) {
  if (gs < 0)
    return false;
  const double a = gs * gs, b = R * R * (tbs * tbs + tbt * tbt);
  if (a > b * (1 + 1e-12))
    return true;
  if (a < b * (1 - 1e-12))
    return false;
  return gs - R * std::hypot(tbs, tbt) >= 0;
}

} // namespace

void FlatJoint::update(Contact& c, Elements e, const ContactKinematics& k, ContactResult& out,
                       EventSink& events) noexcept {
  const FlatJointGeometry& geo = *c.geo;
  if (!c.fixed) { // Eq. 30-31, at the first cycle after installation
    c.R = c.rmul * (k.ball_facet ? k.R1 : std::min(k.R1, k.R2));
    c.fixed = true;
  }
  const double R = c.R;
  // Interface relative motion (Eq. 15, 22), keeping the start-of-step state for Eq. 33.
  const double gs0 = c.gs, tbs0 = c.tbs, tbt0 = c.tbt;
  c.gs += k.d_dn;
  c.dss += k.d_dss;
  c.dst += k.d_dst;
  c.tbs += k.d_tbs;
  c.tbt += k.d_tbt;

  out = ContactResult{};
  // Activity (section 1.6): any element bonded, or the gap negative somewhere.
  bool any_bonded = false;
  for (const auto& el : e)
    any_bonded = any_bonded || el.B == BondState::Bonded;
  // Without bonds, an interface whose smallest gap is not negative carries nothing.
  if (!any_bonded && open_everywhere(c.gs, R, c.tbs, c.tbt)) {
    for (auto& el : e) {
      if (el.slip)
        events.slip_change(false, static_cast<std::int32_t>(&el - e.data()) + 1);
      const double E_slip = el.E_slip;
      el = FlatJointElement{.E_slip = E_slip, .B = el.B};
    }
    return;
  }

  ElementStep step{c, geo, k, events, gs0, tbs0, tbt0};
  for (std::size_t i = 0; i < e.size(); ++i) {
    step.i = i;
    step.run(e[i]);
  }

  // Eq. 23-24: statically equivalent force and moment at the interface centre.
  for (std::size_t i = 0; i < e.size(); ++i) {
    const FlatJointElement& el = e[i];
    const double se = geo.s[i] * R, te = geo.t[i] * R;
    out.Fn += el.Fn;
    out.Fss += el.Fss;
    out.Fst += el.Fst;
    out.Mt += se * el.Fst - te * el.Fss + el.Mt;
    out.Mbs += -te * el.Fn + el.Mbs;
    out.Mbt += se * el.Fn + el.Mbt;
  }
  if (k.dim == 2)
    out.Mt = out.Mbt = out.Fss = 0;
}

ContactStiffness FlatJoint::stiffness(const Contact& c) {
  // Eq. 41-42
  const double R = c.R;
  const int dim = c.geo->dim;
  const double A = dim == 2 ? 2 * R : kPi * R * R;
  const double I = dim == 2 ? 2.0 / 3.0 * R * R * R : 0.25 * kPi * R * R * R * R;
  const double J = dim == 2 ? 0.0 : 0.5 * kPi * R * R * R * R;
  return {(c.kn + c.ks) * A, c.ks * A, c.kn * I + c.ks * J};
}

ContactEnergy FlatJoint::energy(const Contact& c, ConstElements e) {
  ContactEnergy out;
  const int dim = c.geo->dim;
  for (std::size_t i = 0; i < e.size(); ++i) {
    const double A = c.geo->A[i] * (dim == 2 ? c.R : c.R * c.R);
    out.strain += element_strain_energy(c, e[i], i, A, dim); // Eq. 36
    out.slip += e[i].E_slip;                                 // Eq. 38
  }
  return out;
}

bool FlatJoint::keeps_alive(const Contact& c, ConstElements e) {
  for (const auto& el : e)
    if (el.B == BondState::Bonded)
      return true;
  return std::sqrt(c.gs * c.gs + c.dss * c.dss + c.dst * c.dst) <= 2 * c.R;
}

BondView FlatJoint::bond_view(const Contact& c, ConstElements e) {
  BondView v;
  for (const FlatJointElement& el : e) {
    v.intact += el.B == BondState::Bonded;
    v.broken += el.B == BondState::Tension || el.B == BondState::Shear;
  }
  if (v.intact + v.broken > 0) // a gapped or slit joint has no bond to draw
    v.parts = c.n_elem;
  return v;
}

void FlatJoint::call(Contact& c, Elements e, const MethodArgs& m) {
  if (m.element > static_cast<int>(e.size()))
    throw std::invalid_argument("flat-joint method '" + std::string(m.name) + "': element " +
                                std::to_string(m.element) + " is out of range [1, " +
                                std::to_string(e.size()) + "]");
  const auto part = m.element > 0 ? e.subspan(static_cast<std::size_t>(m.element - 1), 1) : e;
  const std::size_t first = m.element > 0 ? static_cast<std::size_t>(m.element - 1) : 0;
  if (m.gap < m.gap_lo || m.gap > m.gap_hi) // the method's gap filter, as for the other models
    return;
  if (m.name == "bond")
    flatjoint::bond(c, part, first);
  else
    flatjoint::unbond(c, part);
}

FlatJoint::Props FlatJoint::read(JsonObject& p, int dim) {
  Props fj;
  fj.fj_Nr = static_cast<int>(p.integer("fj_Nr", 1, 1000, 2));
  fj.fj_Nal = static_cast<int>(p.integer("fj_Nal", 3, 1000, 4));
  if (dim == 2 && p.has("fj_Nal"))
    p.fail("fj_Nal", "is a 3D property (2D flat joints have fj_Nr elements only)");
  fj.fj_rmul = p.number("fj_rmul", Range::at_least(kMinRadiusMultiplier), 1.0);
  fj.fj_gap0 = p.number("fj_gap0", Range::non_negative(), 0.0, "m");
  const StiffnessPair k = read_stiffness_pair(p, "fj_", "Pa/m", false);
  fj.fj_kn = k.kn, fj.fj_ks = k.ks, fj.fj_emod = k.emod, fj.fj_kratio = k.kratio;
  fj.fj_fric = p.number("fj_fric", Range::non_negative(), 0.0);
  fj.fj_ten = p.number("fj_ten", Range::non_negative(), 0.0, "Pa");
  fj.fj_coh = p.number("fj_coh", Range::non_negative(), 0.0, "Pa");
  fj.fj_fa = p.number("fj_fa", Range::half_open(0, 90), 0.0, "deg");
  fj.fj_exact = p.boolean("fj_exact", false);
  if (dim == 2 && fj.fj_exact)
    p.fail("fj_exact", "is a 3D option (the 2D element integrals are always exact)");
  // true bonds every new contact whatever its gap (the elements' own gap is fj_gap0)
  const BondOption b = read_bond_option(p, false, 1e300);
  fj.bond = b.bond, fj.bond_gap_lo = b.lo, fj.bond_gap_hi = b.hi, fj.bond_gap_ratio = b.ratio;
  if (fj.bond && fj.fj_gap0 > 0)
    p.fail("bond", "only elements with a zero gap can be bonded, but fj_gap0 > 0");
  return fj;
}

nlohmann::json FlatJoint::state_json(const Contact& f, ConstElements els, int dim) {
  nlohmann::json j{{"fj_radius", f.R},
                   {"fj_gap", f.gs},
                   {"fj_kn", f.kn},
                   {"fj_ks", f.ks},
                   {"fj_mtype", f.mtype},
                   {"fj_Nr", f.geo->Nr},
                   {"fj_Nal", f.geo->Nal},
                   {"fj_exact", f.exact},
                   {"fj_relbr", nlohmann::json::array({f.tbs, f.tbt})},
                   {"fj_relsd", nlohmann::json::array({f.dss, f.dst})}};
  nlohmann::json elements = nlohmann::json::array();
  for (std::size_t i = 0; i < els.size(); ++i) {
    const FlatJointElement& e = els[i];
    const double A = f.geo->A[i] * (dim == 2 ? f.R : f.R * f.R);
    const double se = f.geo->s[i] * f.R, te = f.geo->t[i] * f.R;
    elements.push_back({{"e", i + 1},
                        {"fj_state", e.B},
                        {"fj_slip", e.slip},
                        {"fj_area", A},
                        {"fj_cen_st", nlohmann::json::array({se, te})},
                        {"fj_egap", flatjoint::gap_at(f, se, te)},
                        {"fj_sigma", e.Fn / A},
                        {"fj_tau", std::hypot(e.Fss, e.Fst) / A},
                        {"force", {{"Fn", e.Fn}, {"Fss", e.Fss}, {"Fst", e.Fst}}},
                        {"moment", {{"Mt", e.Mt}, {"Mbs", e.Mbs}, {"Mbt", e.Mbt}}},
                        {"E_slip", e.E_slip}});
  }
  j["elements"] = std::move(elements);
  return j;
}

std::string FlatJoint::check_loaded(const Contact& c, const Pool& pool) {
  if (std::size_t{c.elem} + c.n_elem > pool.all.size())
    return "flat-joint elements outside the element pool";
  if (c.geo == nullptr || c.n_elem != c.geo->A.size())
    return "flat-joint element count does not match its discretisation";
  if (c.mtype < 1 || c.mtype > 4)
    return "flat-joint type " + std::to_string(c.mtype) + " (1 to 4 allowed)";
  return {};
}

} // namespace rocklab
