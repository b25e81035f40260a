// Smooth-joint model (`smoothjoint`): a planar interface whose orientation is fixed by dip and dip
// direction, independent of the contact normal; bonded or frictional with dilation, no moment
// (smooth-joint-model.md). Stiffnesses are per unit area, stresses in Pa.
#pragma once

#include "contact/contact_model.hpp"

#include <cstdint>
#include <string_view>

namespace rocklab {

struct SmoothJointProps {
  double sj_kn = 0;        ///< normal stiffness per unit area [Pa/m]
  double sj_ks = 0;        ///< shear stiffness per unit area [Pa/m]
  double sj_fric = 0;      ///< friction coefficient [-]
  double sj_da = 0;        ///< dilation angle psi [deg]
  double sj_ten = 0;       ///< tensile strength [Pa]
  double sj_coh = 0;       ///< cohesion [Pa]
  double sj_fa = 0;        ///< friction angle [deg]
  double sj_rmul = 1.0;    ///< radius multiplier [-]
  bool sj_large = false;   ///< large-strain mode
  double dip = 0;          ///< dip theta_p [deg]
  double ddir = 0;         ///< dip direction theta_d [deg] (3D)
  bool use_normal = false; ///< give the joint normal directly instead of dip / dip direction
  Vec3 normal = Vec3::UnitZ();
  bool bond = false;                            ///< apply the bond method at creation
  double bond_gap_lo = -1e300, bond_gap_hi = 0; ///< bond if g_c lies in [lo, hi] [m]
  bool bond_gap_ratio = false; ///< lo, hi are fractions of R1 + R2 (specimen version >= 7)
};

struct SmoothJointContact {
  double kn = 0, ks = 0, fric = 0, tan_da = 0, ten = 0, coh = 0, tan_fa = 0, rmul = 1;
  bool large = false;
  Vec3 nj = Vec3::UnitZ(); ///< joint normal, pointing into the surface of piece 2
  double A = 0;            ///< joint area pi R^2 (2D: 2 R, unit thickness) [m^2]
  double un = 0;           ///< accumulated normal displacement, > 0 closing (Eq. 4) [m]
  Vec3 us = Vec3::Zero();  ///< accumulated shear displacement (Eq. 4) [m]
  double gj = 0;           ///< joint gap, > 0 open [m]
  double Fn = 0;           ///< normal force along nj, > 0 tension [N]
  Vec3 Fs = Vec3::Zero();  ///< shear force on the joint plane [N]
  double E_slip = 0;       ///< [J]
  BondState state = BondState::None;
  bool slip = false;
};

namespace smoothjoint {

/// The joint normal of Eq. 1 from dip and dip direction in degrees.
Vec3 joint_normal(int dim, double dip_deg, double ddir_deg);

/// The update on global vectors: the force is along the joint, not the contact normal.
/// d_delta is the relative displacement increment of piece 2 at the contact [m].
void update_global(SmoothJointContact& c, const Vec3& d_delta, double gap, Vec3& force,
                   EventSink& events) noexcept;
void bond(SmoothJointContact& c, double gap, double lo, double hi);
void unbond(SmoothJointContact& c, double gap, double lo, double hi);
/// sj_setforce (Eq. 20): the normal force from a contact force.
inline void set_force(SmoothJointContact& c, const Vec3& Fc) {
  c.Fn = Fc.dot(c.nj);
}

} // namespace smoothjoint

/// The smooth-joint model: traits for the registry (contact_model.hpp).
struct SmoothJoint {
  static constexpr std::string_view name = "smoothjoint";
  static constexpr bool ball_facet = false; ///< installed at ball-ball contacts only
  using Props = SmoothJointProps;
  using Contact = SmoothJointContact;

  /// ci.n is the contact normal at creation (piece 1 to piece 2), used to assign surfaces.
  static Contact make(const Props& p, const CreationInfo& ci);
  /// The joint works on its own plane: it takes the global increment and gives back the global
  /// force in contact-plane components.
  static void update(Contact& c, const ContactKinematics& k, ContactResult& out,
                     EventSink& events) noexcept {
    const Vec3 d = k.d_dn * k.n + k.d_dss * k.s + k.d_dst * k.t;
    Vec3 F;
    smoothjoint::update_global(c, d, k.gap, F, events);
    out = ContactResult{-F.dot(k.n), F.dot(k.s), F.dot(k.t), 0, 0, 0};
  }
  static ContactStiffness stiffness(const Contact& c) {
    return {(c.kn + c.ks) * c.A, c.ks * c.A, 0.0};
  }
  static ContactEnergy energy(const Contact& c);
  /// Small-strain joints are never deleted; large-strain joints only while bonded.
  static bool keeps_alive(const Contact& c) { return !c.large || c.state == BondState::Bonded; }
  /// A joint is drawn whether bonded or not (it marks the joint plane).
  static BondView bond_view(const Contact& c) {
    const bool intact = c.state == BondState::Bonded;
    const bool broken = c.state == BondState::Tension || c.state == BondState::Shear;
    return {1, intact ? 1 : 0, broken ? 1 : 0};
  }
  static void inherit(Props& p, const SurfaceProps& a, const SurfaceProps& b) {
    inherit_series(p.sj_kn, a.sj_kn, b.sj_kn);
    inherit_series(p.sj_ks, a.sj_ks, b.sj_ks);
    inherit_minimum(p.sj_fric, a.sj_fric, b.sj_fric);
  }
  /// Settable properties: sj_fric [-].
  static double* property(Contact& c, std::string_view name) {
    return name == "sj_fric" ? &c.fric : nullptr;
  }
  static constexpr std::string_view methods[] = {"bond", "unbond", "sj_setforce"};
  static void call(Contact& c, const MethodArgs& m) {
    if (m.name == "bond")
      smoothjoint::bond(c, m.gap, m.gap_lo, m.gap_hi);
    else if (m.name == "unbond")
      smoothjoint::unbond(c, m.gap, m.gap_lo, m.gap_hi);
    else
      smoothjoint::set_force(c, m.force);
  }
  static Props read(JsonObject& p, int dim);
  static nlohmann::json state_json(const Contact& c, int dim);

  template <class A> static void io(A& a, Props& p) {
    a(p.sj_kn), a(p.sj_ks), a(p.sj_fric), a(p.sj_da), a(p.sj_ten), a(p.sj_coh), a(p.sj_fa),
        a(p.sj_rmul), a(p.sj_large), a(p.dip), a(p.ddir), a(p.use_normal), a(p.normal), a(p.bond),
        a(p.bond_gap_lo), a(p.bond_gap_hi);
    if (a.version >= 7)
      a(p.bond_gap_ratio);
  }
  template <class A> static void io(A& a, Contact& c) {
    a(c.kn), a(c.ks), a(c.fric), a(c.tan_da), a(c.ten), a(c.coh), a(c.tan_fa), a(c.rmul),
        a(c.large), a(c.nj), a(c.A), a(c.un), a(c.us), a(c.gj), a(c.Fn), a(c.Fs), a(c.E_slip),
        a(c.state), a(c.slip);
  }
};

} // namespace rocklab
