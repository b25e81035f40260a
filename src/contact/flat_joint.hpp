// Flat-joint contact model (`flatjoint`), 2D and 3D (flat-joint-contact-model.md, section 1).
// The interface between two notional faces is split into elements, each bonded or unbonded;
// the contact force and moment are the statically equivalent sum of the element loads (Eq. 23).
#pragma once

#include "contact/contact_model.hpp"

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace rocklab {

/// Properties a scene assigns (names of the memo's Table 3/5). Stresses in Pa, stiffness Pa/m.
struct FlatJointProps {
  int fj_Nr = 2;         ///< elements in the radial direction (2D: number of elements), >= 1
  int fj_Nal = 4;        ///< elements in the circumferential direction (3D), >= 3
  double fj_rmul = 1.0;  ///< radius multiplier lambda, (0, +inf)
  double fj_gap0 = 0;    ///< initial surface gap g_o [m], >= 0
  double fj_kn = 0;      ///< normal stiffness [Pa/m]
  double fj_ks = 0;      ///< shear stiffness [Pa/m]
  double fj_fric = 0;    ///< friction coefficient mu
  double fj_ten = 0;     ///< tensile strength sigma_c [Pa]
  double fj_coh = 0;     ///< cohesion c [Pa]
  double fj_fa = 0;      ///< friction angle phi [deg], [0, 90)
  double fj_emod = 0;    ///< > 0: deformability, kn = E*/L (Eq. 40) [Pa]
  double fj_kratio = 0;  ///< kappa* = kn/ks for the deformability method
  bool bond = false;     ///< apply the bond method (all elements) when the contact is created
  bool fj_exact = false; ///< 3D: integrate element normal and twist-shear stresses exactly
};

/// Element state (memo Table 4, per element).
struct FlatJointElement {
  double Fn = 0;           ///< normal force, > 0 tension [N]
  double Fss = 0, Fst = 0; ///< shear force [N]
  double Mbs = 0, Mbt = 0; ///< bending moment about the element centroid [N m]
  double Mt = 0;           ///< twisting moment about the element centroid (exact 3D) [N m]
  double E_slip = 0;       ///< slip energy (Eq. 39) [J]
  std::uint8_t B = 0;      ///< 0 unbonded, 1 broke in tension, 2 broke in shear, 3 bonded
  bool slip = false;
};

/// Unit-radius element geometry of one discretisation (Eq. 13, 16-17), shared by all contacts.
struct FlatJointGeometry {
  int dim = 3, Nr = 2, Nal = 4;
  std::vector<double> A, s, t;           ///< area and centroid for R = 1
  std::vector<double> r1, r2, a1, a2;    ///< 3D annular sector bounds (R = 1)
  std::vector<double> Ixx, Ixy, Iyy, Jp; ///< 3D second moments about the centre (R = 1)
};
const FlatJointGeometry& flat_joint_geometry(int dim, int Nr, int Nal);

struct FlatJointContact {
  // parameters (per contact)
  double kn = 0, ks = 0, fric = 0, ten = 0, coh = 0, tan_fa = 0, rmul = 1, gap0 = 0;
  const FlatJointGeometry* geo = nullptr;
  std::uint32_t elem = 0; ///< index of element 1 in the batch's element array
  std::uint16_t n_elem = 0;
  bool exact = false;
  // state
  bool fixed = false;      ///< Eq. 30-31 applied
  std::uint8_t mtype = 4;  ///< 1 bonded, 2 gapped, 3 slit, 4 other
  double R = 0;            ///< flat-joint radius [m]
  double gs = 0;           ///< surface gap [m]
  double dss = 0, dst = 0; ///< relative shear displacement [m]
  double tbs = 0, tbt = 0; ///< relative bend rotation [rad] (2D: theta_bk = -tbs)
};

namespace flatjoint {

/// Create a contact: parameters, radius (Eq. 30), elements appended to `elements`.
FlatJointContact make(const FlatJointProps& p, int dim, double R1, double R2, bool ball_facet,
                      std::vector<FlatJointElement>& elements);
void update(FlatJointContact& c, std::span<FlatJointElement> e, const ContactKinematics& k,
            ContactResult& out, EventSink& events) noexcept;
ContactStiffness stiffness(const FlatJointContact& c);
ContactEnergy energy(const FlatJointContact& c, std::span<const FlatJointElement> e);
/// Active if any element is bonded or the interface gap is negative somewhere (section 1.6);
/// may be deleted once the notional surfaces are a flat-joint diameter apart.
bool keeps_alive(const FlatJointContact& c, std::span<const FlatJointElement> e);
/// The bond method: bond every element whose gap is zero over its whole surface (`first` is the
/// index of e[0] among the contact's elements).
void bond(FlatJointContact& c, std::span<FlatJointElement> e, std::size_t first = 0);
void unbond(FlatJointContact& c, std::span<FlatJointElement> e);

/// Gap at a point (s, t) of the interface (Eq. 14, 21).
inline double gap_at(const FlatJointContact& c, double s, double t) {
  return c.gs + t * c.tbs - s * c.tbt;
}

/// Integrals of 1, s, t, s^2, s t, t^2 over a region [m^2 .. m^4].
using Moments = std::array<double, 6>;
/// Exact moments of the part of the annular sector r1 <= r <= r2, a1 <= alpha <= a2 where the
/// gap gs + bs s + bt t is negative (Green's theorem: analytic on arcs, exact Gauss on lines).
Moments clipped_moments(double r1, double r2, double a1, double a2, double gs, double bs,
                        double bt);

/// 2D element normal force and bending moment from the end gaps (Eq. 44-49), per unit thickness.
/// Returns Fn (> 0 tension) and Mb (about k).
void element_2d(double kn, double rbar, double ga, double gb, bool bonded, double& Fn, double& Mb);

} // namespace flatjoint
} // namespace rocklab
