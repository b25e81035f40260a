// Flat-joint contact model (`flatjoint`), 2D and 3D (flat-joint-contact-model.md, section 1).
// The interface between two notional faces is split into elements, each bonded or unbonded;
// the contact force and moment are the statically equivalent sum of the element loads (Eq. 23).
#pragma once

#include "contact/contact_model.hpp"
#include "io/input_error.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
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
  /// ... if its creation gap is in [lo, hi]: m, or fractions of R1 + R2 (file version >= 7)
  double bond_gap_lo = -1e300, bond_gap_hi = 1e300;
  bool bond_gap_ratio = false;
};

/// Element state (memo Table 4, per element).
struct FlatJointElement {
  double Fn = 0;                 ///< normal force, > 0 tension [N]
  double Fss = 0, Fst = 0;       ///< shear force [N]
  double Mbs = 0, Mbt = 0;       ///< bending moment about the element centroid [N m]
  double Mt = 0;                 ///< twisting moment about the element centroid (exact 3D) [N m]
  double E_slip = 0;             ///< slip energy (Eq. 39) [J]
  BondState B = BondState::None; ///< bond state of the element
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

/// The elements of every flat joint of a batch, contact by contact (the model's Pool).
struct FlatJointElements {
  std::vector<FlatJointElement> all;

  std::span<FlatJointElement> of(const FlatJointContact& c) {
    assert(std::size_t{c.elem} + c.n_elem <= all.size() && "flat-joint elements outside the pool");
    return {all.data() + c.elem, c.n_elem};
  }
  std::span<const FlatJointElement> of(const FlatJointContact& c) const {
    assert(std::size_t{c.elem} + c.n_elem <= all.size() && "flat-joint elements outside the pool");
    return {all.data() + c.elem, c.n_elem};
  }
  void clear() { all.clear(); }
  std::size_t size() const { return all.size(); }

  // Rebuilding the batch in place (Model::rebuild_contacts): the contacts' elements lie in slot
  // order without holes ("packed"); kept contacts move to the front, then everything moves to
  // its final place from the back, so no second copy of the pool is ever made.
  bool packed(std::span<const FlatJointContact> contacts) const {
    std::size_t at = 0;
    for (const FlatJointContact& c : contacts) {
      if (c.elem != at)
        return false;
      at += c.n_elem;
    }
    return at == all.size();
  }
  /// Move c's elements to start at `at` (<= where they are); returns the index after them.
  std::size_t pack_to(FlatJointContact& c, std::size_t at) {
    assert(at <= c.elem && "elements move toward the front");
    if (at != c.elem)
      std::move(all.begin() + c.elem, all.begin() + c.elem + c.n_elem, all.begin() + at);
    c.elem = static_cast<std::uint32_t>(at);
    return at + c.n_elem;
  }
  /// Move c's elements to end at `end` (their end <= `end`); returns where they now start.
  std::size_t place_before(FlatJointContact& c, std::size_t end) {
    const std::size_t at = end - c.n_elem;
    assert(at >= c.elem && "elements move toward the back");
    if (at != c.elem)
      std::move_backward(all.begin() + c.elem, all.begin() + c.elem + c.n_elem,
                         all.begin() + static_cast<std::ptrdiff_t>(end));
    c.elem = static_cast<std::uint32_t>(at);
    return at;
  }
  /// Copy c's elements from another pool to end at `end`; returns where they now start.
  std::size_t copy_before(const FlatJointElements& from, FlatJointContact& c, std::size_t end) {
    const auto e = from.of(c);
    const std::size_t at = end - c.n_elem;
    std::copy(e.begin(), e.end(), all.begin() + static_cast<std::ptrdiff_t>(at));
    c.elem = static_cast<std::uint32_t>(at);
    return at;
  }
  /// Copy a contact's elements from another pool; returns the contact pointing at the copy.
  FlatJointContact adopt(const FlatJointElements& from, FlatJointContact c) {
    const auto e = from.of(c);
    c.elem = static_cast<std::uint32_t>(all.size());
    all.insert(all.end(), e.begin(), e.end());
    return c;
  }
};

/// The flat-joint model: traits for the registry (contact_model.hpp). Functions that read element
/// state take the contact's elements beside it.
struct FlatJoint {
  static constexpr std::string_view name = "flatjoint";
  using Props = FlatJointProps;
  using Contact = FlatJointContact;
  using Pool = FlatJointElements;
  using Elements = std::span<FlatJointElement>;
  using ConstElements = std::span<const FlatJointElement>;

  /// Create a contact: parameters, radius (Eq. 30), elements appended to the pool.
  static Contact make(const Props& p, const CreationInfo& ci, Pool& pool);
  static void update(Contact& c, Elements e, const ContactKinematics& k, ContactResult& out,
                     EventSink& events) noexcept;
  static ContactStiffness stiffness(const Contact& c);
  static ContactEnergy energy(const Contact& c, ConstElements e);
  /// Active if any element is bonded or the interface gap is negative somewhere (section 1.6);
  /// may be deleted once the notional surfaces are a flat-joint diameter apart.
  static bool keeps_alive(const Contact& c, ConstElements e);
  static BondView bond_view(const Contact& c, ConstElements e);
  /// Settable properties: fj_fric [-].
  static double* property(Contact& c, std::string_view name) {
    return name == "fj_fric" ? &c.fric : nullptr;
  }
  static constexpr std::string_view methods[] = {"bond", "unbond"};
  /// bond / unbond, on every element or on element `args.element` (1..N).
  static void call(Contact& c, Elements e, const MethodArgs& args);
  static Props read(JsonObject& p, int dim);
  static nlohmann::json state_json(const Contact& c, ConstElements e, int dim);
  /// A card's "flatjoint" section (card_bonding.hpp, flat_joint_card.cpp): each candidate is
  /// bonded, gapped or slit by the card's fractions, its strengths drawn per contact.
  static constexpr std::string_view card_section = "flatjoint";
  static constexpr std::string_view card_counts[] = {"bonded", "gapped", "slit"};
  static std::unique_ptr<CardBonding> card_bonding(JsonObject& top, int dim);

  template <class A> static void io(A& a, Props& p) {
    a(p.fj_Nr), a(p.fj_Nal), a(p.fj_rmul), a(p.fj_gap0), a(p.fj_kn), a(p.fj_ks), a(p.fj_fric),
        a(p.fj_ten), a(p.fj_coh), a(p.fj_fa), a(p.fj_emod), a(p.fj_kratio), a(p.bond),
        a(p.fj_exact);
    if (a.version >= 7)
      a(p.bond_gap_lo), a(p.bond_gap_hi), a(p.bond_gap_ratio);
  }
  template <class A> static void io(A& a, Contact& c) {
    a(c.kn), a(c.ks), a(c.fric), a(c.ten), a(c.coh), a(c.tan_fa), a(c.rmul), a(c.gap0);
    int dim = c.geo ? c.geo->dim : 3, nr = c.geo ? c.geo->Nr : 1, nal = c.geo ? c.geo->Nal : 3;
    a(dim), a(nr), a(nal);
    if constexpr (A::reading) {
      if ((dim != 2 && dim != 3) || nr < 1 || nal < 1 || nr > 1000 || nal > 1000)
        throw InputError("corrupt specimen body (flat-joint discretisation)");
      c.geo = &flat_joint_geometry(dim, nr, nal);
    }
    a(c.elem), a(c.n_elem), a(c.exact), a(c.fixed), a(c.mtype), a(c.R), a(c.gs), a(c.dss), a(c.dst),
        a(c.tbs), a(c.tbt);
  }
  template <class A> static void io(A& a, FlatJointElement& e) {
    a(e.Fn), a(e.Fss), a(e.Fst), a(e.Mbs), a(e.Mbt), a(e.Mt), a(e.E_slip), a(e.B), a(e.slip);
  }
  template <class A> static void io(A& a, Pool& pool) {
    a.vec(pool.all, [&](FlatJointElement& e) { io(a, e); });
  }
  /// A contact read from a file: its elements inside the pool, as many as its discretisation
  /// has, its type known; else what is wrong.
  static std::string check_loaded(const Contact& c, const Pool& pool);
};

} // namespace rocklab
