// Linear parallel bond model (`linearpbond`): the linear component with dashpots acting in
// parallel with a finite-size bond that carries force and moment (linear-parallel-bond-model.md).
#pragma once

#include "contact/linear.hpp"

namespace rocklab {

/// Properties a scene assigns (names as in the seed's Table 2). Stresses in Pa.
struct PBondProps {
  LinearProps linear;   ///< the linear component (kn, ks, fric, dashpots, ...)
  double pb_rmul = 1.0; ///< radius multiplier lambda-bar [-], (0, +inf)
  double pb_kn = 0;     ///< bond normal stiffness [Pa/m]
  double pb_ks = 0;     ///< bond shear stiffness [Pa/m]
  double pb_mcf = 1.0;  ///< moment-contribution factor beta-bar [-], [0, 1]
  double pb_ten = 0;    ///< tensile strength sigma-bar_c [Pa]
  double pb_coh = 0;    ///< cohesion c-bar [Pa]
  double pb_fa = 0;     ///< friction angle phi-bar [deg], [0, 90)
  double pb_emod = 0;   ///< > 0: pb_deformability, kn-bar = E*/L (Eq. 16) [Pa]
  double pb_kratio = 0; ///< kappa-bar* for pb_deformability [-]
  bool bond = true;     ///< apply the bond method when the contact is created
  double bond_gap_lo = -1e300, bond_gap_hi = 0; ///< bond if g_c is in [lo, hi] [m]
};

struct PBondParams {
  double rmul = 1, kn = 0, ks = 0, mcf = 1, ten = 0, coh = 0, tan_fa = 0;
};

/// Bond state B-bar: 0 unbonded, 1 broke in tension, 2 broke in shear, 3 bonded.
struct PBondState {
  double Fn = 0;           ///< bond normal force, > 0 tension [N]
  double Fss = 0, Fst = 0; ///< bond shear force [N]
  double Mt = 0;           ///< twisting moment [N m] (3D)
  double Mbs = 0, Mbt = 0; ///< bending moment [N m]
  double gs = 0; ///< bond surface gap, cumulative normal displacement since bonding (Eq. 4) [m]
  double sigma = 0, tau = 0;         ///< peripheral stresses of the last update (Eq. 12) [Pa]
  double R = 0, A = 0, I = 0, J = 0; ///< bond cross-section of the last update (Eq. 5)
  std::uint8_t state = 0;
};

struct PBondContact {
  LinearParams lp;
  LinearState ls;
  PBondParams p;
  PBondState s;
};

/// Bond cross-section (Eq. 5): radius, area, moment of inertia, polar moment.
struct BondSection {
  double R, A, I, J;
};
BondSection bond_section(double rmul, int dim, double R1, double R2, bool ball_facet);

namespace pbond {

PBondContact make(const PBondProps& p, int dim, double R1, double R2, bool ball_facet, double gap);
void update(PBondContact& c, const ContactKinematics& k, ContactResult& out,
            EventSink& events) noexcept;
ContactStiffness stiffness(const PBondContact& c);
ContactEnergy energy(const PBondContact& c);
inline bool keeps_alive(const PBondContact& c) {
  return c.s.state == 3;
}
/// The bond method: bond if the contact gap lies in [lo, hi] (force and moment zeroed).
void bond(PBondContact& c, double gap, double lo, double hi);
/// The unbond method: state becomes 0; force and moment are left to the next update.
void unbond(PBondContact& c, double gap, double lo, double hi);

} // namespace pbond
} // namespace rocklab
