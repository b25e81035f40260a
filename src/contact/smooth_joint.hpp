// Smooth-joint model (`smoothjoint`): a planar interface whose orientation is fixed by dip and dip
// direction, independent of the contact normal; bonded or frictional with dilation, no moment
// (smooth-joint-model.md). Stiffnesses are per unit area, stresses in Pa.
#pragma once

#include "contact/contact_model.hpp"

#include <cstdint>

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
  std::uint8_t state = 0;  ///< 0 unbonded, 1 broke in tension, 2 broke in shear, 3 bonded
  bool slip = false;
};

/// The joint normal of Eq. 1 from dip and dip direction in degrees.
Vec3 joint_normal(int dim, double dip_deg, double ddir_deg);

namespace smoothjoint {

/// n_c is the contact normal at creation (piece 1 to piece 2), used to assign surfaces.
SmoothJointContact make(const SmoothJointProps& p, int dim, double R1, double R2, const Vec3& n_c,
                        double gap);
/// The update works on global vectors: the force is along the joint, not the contact normal.
/// d_delta is the relative displacement increment of piece 2 at the contact [m].
void update(SmoothJointContact& c, const Vec3& d_delta, double gap, Vec3& force,
            EventSink& events) noexcept;
ContactStiffness stiffness(const SmoothJointContact& c);
ContactEnergy energy(const SmoothJointContact& c);
/// Small-strain joints are never deleted; large-strain joints only while bonded.
inline bool keeps_alive(const SmoothJointContact& c) {
  return !c.large || c.state == 3;
}
void bond(SmoothJointContact& c, double gap, double lo, double hi);
void unbond(SmoothJointContact& c, double gap, double lo, double hi);
/// sj_setforce (Eq. 20): the normal force from a contact force.
inline void set_force(SmoothJointContact& c, const Vec3& Fc) {
  c.Fn = Fc.dot(c.nj);
}

} // namespace smoothjoint
} // namespace rocklab
