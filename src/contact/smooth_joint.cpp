#include "contact/smooth_joint.hpp"

#include "io/json_input.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace rocklab {

namespace {
constexpr double kDeg = std::numbers::pi / 180.0;
}

namespace smoothjoint {

Vec3 joint_normal(int dim, double dip_deg, double ddir_deg) {
  const double p = dip_deg * kDeg, d = ddir_deg * kDeg;
  if (dim == 2)
    return Vec3(std::sin(p), std::cos(p), 0);                                     // Eq. 1, 2D
  return Vec3(std::sin(p) * std::sin(d), std::sin(p) * std::cos(d), std::cos(p)); // Eq. 1, 3D
}

} // namespace smoothjoint

SmoothJoint::Contact SmoothJoint::make(const Props& p, const CreationInfo& ci) {
  using namespace smoothjoint;
  const int dim = ci.dim;
  const double R1 = ci.R1, R2 = ci.R2;
  const Vec3& n_c = ci.n;
  Contact c;
  c.kn = p.sj_kn;
  c.ks = p.sj_ks;
  c.fric = p.sj_fric;
  c.tan_da = std::tan(p.sj_da * kDeg);
  c.ten = p.sj_ten;
  c.coh = p.sj_coh;
  c.tan_fa = std::tan(p.sj_fa * kDeg);
  c.rmul = p.sj_rmul;
  c.large = p.sj_large;
  const double R = c.rmul * std::min(R1, R2); // Eq. 2
  c.A = dim == 2 ? 2 * R : std::numbers::pi * R * R;
  // Piece 2 lies in surface 2 iff n_c . n_j >= 0; orient n_j from piece 1's surface to 2's.
  const Vec3 nj = p.use_normal ? Vec3(p.normal.normalized()) : joint_normal(dim, p.dip, p.ddir);
  c.nj = n_c.dot(nj) >= 0 ? nj : Vec3(-nj);
  if (p.bond) {
    const double s = bond_gap_scale(ci, p.bond_gap_ratio);
    bond(c, ci.gap, s * p.bond_gap_lo, s * p.bond_gap_hi);
  }
  return c;
}

namespace smoothjoint {

void bond(SmoothJointContact& c, double gap, double lo, double hi) {
  if (gap >= lo && gap <= hi)
    c.state = BondState::Bonded;
}

void unbond(SmoothJointContact& c, double gap, double lo, double hi) {
  if (gap >= lo && gap <= hi)
    c.state = BondState::None;
}

void update_global(SmoothJointContact& c, const Vec3& d_delta, double gap, Vec3& force,
                   EventSink& events) noexcept {
  const bool bonded = c.state == BondState::Bonded;
  // Large-strain mode: active only while bonded or overlapping.
  if (c.large && !bonded && gap >= 0) {
    c.Fn = 0;
    c.Fs.setZero();
    force.setZero();
    return;
  }
  // Eq. 3-4: resolve the increment on the joint.
  const double d_n = d_delta.dot(c.nj); // > 0 opening
  const Vec3 d_s = d_delta - d_n * c.nj;
  c.un -= d_n;
  c.us += d_s;
  // Elastic portions: everything while bonded; otherwise the part while the joint gap is < 0.
  const double g0 = c.gj, g1 = c.gj + d_n;
  c.gj = g1;
  double f = 1.0;
  if (!bonded) {
    if (g0 >= 0 && g1 >= 0)
      f = 0;
    else if (g0 < 0 && g1 >= 0)
      f = -g0 / (g1 - g0);
    else if (g0 >= 0 && g1 < 0)
      f = -g1 / (g0 - g1);
  }
  const double kn = c.kn * c.A, ks = c.ks * c.A;
  const double Fn0 = c.Fn;
  const Vec3 Fs0 = c.Fs;
  c.Fn = Fn0 + kn * f * d_n; // Eq. 7
  if (!bonded)
    c.Fn = std::min(c.Fn, 0.0);
  Vec3 trial = Fs0 - ks * f * d_s; // Eq. 8
  const double trial_mag = trial.norm();
  auto coulomb = [&](bool dilate) { // Eq. 9-12
    const double limit = -c.fric * c.Fn;
    const bool slipping = trial_mag > limit;
    if (slipping) {
      c.Fs = trial_mag > 0 ? Vec3(trial * (limit / trial_mag)) : Vec3::Zero();
      // Dilation while slipping: the compressive normal force grows by
      // (|Fs*| - Fs^mu) / ks * kn tan(psi) (Eq. 12; stiffnesses times area).
      if (dilate && ks > 0)
        c.Fn -= (trial_mag - limit) / ks * kn * c.tan_da;
    } else {
      c.Fs = trial;
    }
    if (slipping != c.slip) {
      events.slip_change(slipping);
      c.slip = slipping;
    }
  };
  if (!bonded) {
    coulomb(true);
  } else {
    const double tau_c = c.coh - (c.Fn / c.A) * c.tan_fa;
    int mode = 0;
    if (c.Fn >= c.ten * c.A)
      mode = 1;
    else if (trial_mag >= tau_c * c.A)
      mode = 2; // Eq. 13
    if (mode != 0) {
      Event e;
      e.type = EventType::BondBreak;
      e.mode = mode;
      e.strength = mode == 1 ? c.ten : tau_c;
      e.energy = SmoothJoint::energy(c).strain;
      e.normal = c.nj;
      e.size = 2 * std::sqrt(c.A / std::numbers::pi);
      events.raise(e);
      c.state = broken_state(mode);
      if (mode == 1 || c.Fn > 0) { // Eq. 14
        c.Fn = 0;
        c.Fs.setZero();
      } else {
        coulomb(false); // limited by Eq. 10, no dilation
      }
    } else {
      c.Fs = trial; // Eq. 15
    }
  }
  // Slip energy: minus the work of the mean shear force on the slip part of the increment.
  if (ks > 0) {
    const Vec3 elastic = -(c.Fs - Fs0) / ks;
    const Vec3 mu = d_s - elastic;
    if (c.slip)
      c.E_slip -= 0.5 * (Fs0 + c.Fs).dot(mu); // Eq. 17
  }
  force = -c.Fn * c.nj + c.Fs; // Eq. 5-6
}

} // namespace smoothjoint

ContactEnergy SmoothJoint::energy(const Contact& c) {
  ContactEnergy e; // Eq. 16 with the stiffnesses times the joint area
  if (c.kn > 0)
    e.strain += 0.5 * c.Fn * c.Fn / (c.kn * c.A);
  if (c.ks > 0)
    e.strain += 0.5 * c.Fs.squaredNorm() / (c.ks * c.A);
  e.slip = c.E_slip;
  return e;
}

SmoothJoint::Props SmoothJoint::read(JsonObject& p, int dim) {
  const Range angle = Range::half_open(0, 90);
  Props sj;
  sj.sj_kn = p.number("sj_kn", Range::non_negative(), 0.0, "Pa/m");
  sj.sj_ks = p.number("sj_ks", Range::non_negative(), 0.0, "Pa/m");
  sj.sj_fric = p.number("sj_fric", Range::non_negative(), 0.0);
  sj.sj_da = p.number("sj_da", angle, 0.0, "deg");
  sj.sj_ten = p.number("sj_ten", Range::non_negative(), 0.0, "Pa");
  sj.sj_coh = p.number("sj_coh", Range::non_negative(), 0.0, "Pa");
  sj.sj_fa = p.number("sj_fa", angle, 0.0, "deg");
  sj.sj_rmul = p.number("sj_rmul", Range::positive(), 1.0);
  sj.sj_large = p.boolean("sj_large", false);
  if (p.has("normal")) {
    if (p.has("dip") || p.has("ddir"))
      p.fail("normal", "give either the joint normal or dip / ddir, not both");
    sj.use_normal = true;
    sj.normal = p.vec("normal", dim);
    if (sj.normal.norm() == 0)
      p.fail("normal", "the joint normal must not be the zero vector");
  } else {
    sj.dip = p.number("dip", Range::closed(0, 360), 0.0, "deg");
    sj.ddir = p.number("ddir", Range::closed(0, 360), 0.0, "deg");
    if (dim == 2 && p.has("ddir"))
      p.fail("ddir", "is a 3D property");
  }
  const BondOption b = read_bond_option(p, false);
  sj.bond = b.bond, sj.bond_gap_lo = b.lo, sj.bond_gap_hi = b.hi, sj.bond_gap_ratio = b.ratio;
  return sj;
}

nlohmann::json SmoothJoint::state_json(const Contact& sj, int) {
  auto v3 = [](const Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); };
  return {{"sj_state", sj.state},  {"sj_slip", sj.slip}, {"sj_fn", sj.Fn},     {"sj_fs", v3(sj.Fs)},
          {"sj_unorm", v3(sj.nj)}, {"sj_un", sj.un},     {"sj_us", v3(sj.us)}, {"sj_gap", sj.gj},
          {"sj_area", sj.A},       {"E_slip", sj.E_slip}};
}

} // namespace rocklab
