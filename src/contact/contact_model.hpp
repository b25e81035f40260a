// Interface between the engine and contact models. A contact model is plain data (properties and
// per-contact state) plus pure functions; the engine hands it the kinematics of the step, the model
// returns force and moment in contact-plane coordinates. No I/O, no access to the model.
//
// Each model file declares one traits type (e.g. `struct Linear`) with static members, and
// contact/registry.hpp lists every traits type once (`AllModels`); everything that handles "every
// model" iterates that list. What a traits type M provides (docs/architecture.md, "Add a contact
// model"):
//   name                       the JSON keyword ("linear")
//   Props, Contact             what a scene assigns, and the per-contact parameters + state
//   make(props, info)          a new contact (models with a Pool: make(props, info, pool))
//   update(c, k, out, events)  the force-displacement law (noexcept, pure)
//   stiffness(c), energy(c), keeps_alive(c)
//   read(JsonObject&, dim)     its properties from a contact_models entry (units in the doc)
//   state_json(c, dim)         its state in results.json
//   io(archive, props), io(archive, contact)   specimen and checkpoint files
//   property(c, name)          a settable property (PFC's `contact property`), or nullptr
// and optionally:
//   bond_view(c)               its bond as output shows it (bonded models)
//   inherit(props, a, b)       property inheritance from the pieces' groups
//   methods, call(c, args)     methods called on existing contacts ("bond", "unbond", ...)
//   ball_facet = false         a model for ball-ball contacts only
//   Pool                       per-batch storage shared by the contacts (flat-joint elements);
//                              the functions then take (c, the contact's part of the pool)
#pragma once

#include "core/events.hpp"
#include "core/types.hpp"

#include <nlohmann/json_fwd.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string_view>

namespace rocklab {

class JsonObject;
class CardBonding; ///< a model's card handling (card_bonding.hpp)

/// Kinematic input of one force-displacement update, in contact-plane coordinates
/// (FJ memo Eq. 2 and 11). 2D: d_dss = d_tt = d_tbt = 0 and d_tbs = -d_theta_z.
struct ContactKinematics {
  double dt = 0;       ///< time step [s]
  int dim = 3;         ///< 2 or 3
  double gap = 0;      ///< contact gap g_c, > 0 open [m]
  double d_dn = 0;     ///< relative normal-displacement increment, > 0 opening [m]
  double d_dss = 0;    ///< relative shear-displacement increment along s_c [m]
  double d_dst = 0;    ///< relative shear-displacement increment along t_c [m]
  double d_tt = 0;     ///< relative twist-rotation increment [rad]
  double d_tbs = 0;    ///< relative bend-rotation increment along s_c [rad]
  double d_tbt = 0;    ///< relative bend-rotation increment along t_c [rad]
  double R1 = 0;       ///< radius of piece 1 [m]
  double R2 = 0;       ///< radius of piece 2, 0 for a facet [m]
  double mass_eff = 0; ///< m1 m2 / (m1 + m2), or m1 for ball-facet [kg]
  bool ball_facet = false;
  Vec3 n = Vec3::UnitX(), s = Vec3::UnitY(), t = Vec3::UnitZ(); ///< contact-plane axes
};

/// Output of one update: force and moment acting on piece 2 at the contact location, in
/// contact-plane coordinates (F = -Fn n + Fss s + Fst t, Fn > 0 tension; M = Mt n + Mbs s + Mbt t).
struct ContactResult {
  double Fn = 0, Fss = 0, Fst = 0;
  double Mt = 0, Mbs = 0, Mbt = 0;
};

/// Stiffnesses a contact contributes to the time-step estimate.
struct ContactStiffness {
  double k_tran = 0;  ///< translational, normal + shear [N/m]
  double k_shear = 0; ///< shear part, whose lever arm adds rotational stiffness [N/m]
  double k_rot = 0;   ///< rotational, from bonds [N m/rad]
};

/// Energy partitions of one contact. Stored partitions are current values; dissipated ones are
/// accumulated and >= 0 when energy leaves the system.
struct ContactEnergy {
  double strain = 0;      ///< stored in the springs [J]
  double bond_strain = 0; ///< stored in bond springs [J]
  double slip = 0;        ///< dissipated by frictional slip [J]
  double dashpot = 0;     ///< dissipated by dashpots [J]
  double plastic = 0;     ///< dissipated by plastic deformation [J]

  ContactEnergy& operator+=(const ContactEnergy& o) {
    strain += o.strain;
    bond_strain += o.bond_strain;
    slip += o.slip;
    dashpot += o.dashpot;
    plastic += o.plastic;
    return *this;
  }
};

/// Context a model needs to raise events (the engine fills the location fields later).
struct EventSink {
  EventBuffer* buffer = nullptr;
  std::uint64_t contact = 0;
  std::int32_t seq = 0;
  bool slip_events = true; ///< false: slip_change events are not recorded
  void raise(Event e) noexcept {
    e.contact = contact;
    e.seq = seq++;
    buffer->push_back(e);
  }
  /// slip_change: mode 0 slip began, 1 slip ended; element 1..N for flat joints.
  void slip_change(bool began, std::int32_t element = -1) noexcept {
    if (!slip_events)
      return;
    Event e;
    e.type = EventType::SlipChange;
    e.mode = began ? 0 : 1;
    e.element = element;
    raise(e);
  }
};

/// State of one bond (a parallel bond, a contact bond, a flat-joint element, a smooth joint),
/// stored as one byte: never bonded (or unbonded by a method), broken in tension, broken in shear,
/// intact. The broken codes equal the bond_break event's mode.
enum class BondState : std::uint8_t { None = 0, Tension = 1, Shear = 2, Bonded = 3 };

inline BondState broken_state(int mode) {
  return mode == 1 ? BondState::Tension : BondState::Shear;
}

/// A contact's bond as output shows it: its bondable parts (flat-joint elements; one for the other
/// bonded models) and how many of them are intact or broken. parts == 0: nothing to draw.
struct BondView {
  int parts = 0;
  int intact = 0;
  int broken = 0;
};

/// The view of a model with one bond per contact: nothing to draw if it was never bonded.
inline BondView point_bond_view(BondState s) {
  if (s == BondState::None)
    return {};
  const bool intact = s == BondState::Bonded;
  return {1, intact ? 1 : 0, intact ? 0 : 1};
}

/// Geometry a model may need when a contact is created.
struct CreationInfo {
  int dim = 3;
  double R1 = 0, R2 = 0; ///< piece radii (R2 = 0 for a facet) [m]
  bool ball_facet = false;
  double gap = 0;         ///< contact gap at creation [m]
  Vec3 n = Vec3::UnitX(); ///< contact normal at creation
};

/// Surface properties of the pieces of one group, inherited by contacts whose rule asks for it.
/// NaN: the group does not hold the property.
struct SurfaceProps {
  double kn = std::numeric_limits<double>::quiet_NaN();      ///< [N/m]
  double ks = std::numeric_limits<double>::quiet_NaN();      ///< [N/m]
  double fric = std::numeric_limits<double>::quiet_NaN();    ///< [-]
  double sj_kn = std::numeric_limits<double>::quiet_NaN();   ///< [Pa/m]
  double sj_ks = std::numeric_limits<double>::quiet_NaN();   ///< [Pa/m]
  double sj_fric = std::numeric_limits<double>::quiet_NaN(); ///< [-]
};

/// Property inheritance (smooth-joint Eq. 18-19; the linear properties inherit the same way): the
/// two pieces' stiffnesses act in series and the friction is the smaller one. A property is
/// inherited only when both pieces hold it.
inline void inherit_series(double& k, double k1, double k2) {
  if (!std::isnan(k1) && !std::isnan(k2))
    k = (k1 > 0 && k2 > 0) ? 1.0 / (1.0 / k1 + 1.0 / k2) : 0.0; // Eq. 18
}
inline void inherit_minimum(double& mu, double m1, double m2) {
  if (!std::isnan(m1) && !std::isnan(m2))
    mu = std::min(m1, m2); // Eq. 19
}

/// The `bond` key of a bonded model's properties: whether a new contact is bonded, and for which
/// creation gaps [lo, hi]: in metres, or with `ratio` as fractions of the radii sum.
struct BondOption {
  bool bond = false;
  double lo = -1e300, hi = 0;
  bool ratio = false;
};
/// Reads `bond`: true/false (the gaps (-inf, default_hi]), a maximum gap [m], {"gap": [lo, hi]}
/// in m or {"gap_ratio": [lo, hi]} as fractions of R1 + R2 within [-1, 1]; absent:
/// `default_bond` (model_json.cpp).
BondOption read_bond_option(JsonObject& p, bool default_bond, double default_hi = 0);

/// A model's stiffnesses as its properties give them: either the stiffnesses themselves
/// (`<prefix>kn`, `<prefix>ks`) or the deformability (`<prefix>emod`, `<prefix>kratio`; FJ memo
/// Eq. 40, LPB doc 2.2), never both. One reader for every model (model_json.cpp); kratio is 0 (no
/// shear stiffness, the docs' default) or at least 1e-3 (it divides).
struct StiffnessPair {
  double kn = 0, ks = 0;       ///< given stiffnesses [k_unit]
  double emod = 0, kratio = 0; ///< deformability: effective modulus [Pa], kn/ks [-]
  bool deformability = false;  ///< emod was given
};
StiffnessPair read_stiffness_pair(JsonObject& p, const std::string& prefix, const char* k_unit,
                                  bool kn_required);
/// Lower bound of a radius multiplier (fj_rmul, pb_rmul): a factor the contact divides by.
inline constexpr double kMinRadiusMultiplier = 1e-3;

/// What a creation gap is measured against: 1 (metres) or, for a `gap_ratio` range, the radii
/// sum R1 + R2 (a ball-facet contact: R1), as the run-stage methods' `gap_ratio` does.
inline double bond_gap_scale(const CreationInfo& ci, bool ratio) {
  return ratio ? ci.R1 + ci.R2 : 1.0;
}

/// A method called on existing contacts of one model (scene `methods`).
struct MethodArgs {
  std::string_view name;              ///< "bond", "unbond", "sj_setforce"
  double gap_lo = -1e300, gap_hi = 0; ///< act where the contact gap is in [lo, hi] [m]
  int element = 0;                    ///< flat joints: element 1..N, 0 all
  double gap = 0;                     ///< this contact's gap [m]
  Vec3 force = Vec3::Zero();          ///< this contact's force on piece 2 [N]
};

} // namespace rocklab
