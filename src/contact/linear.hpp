// Linear contact model (PFC `linear`): linear springs with Coulomb slip and optional dashpots.
// The linear component is also the first interface of the linear parallel bond model
// (linear-parallel-bond-model.md, Eq. 1), where the formulation is referenced.
#pragma once

#include "contact/contact_model.hpp"

#include <cstdint>
#include <numbers>
#include <string_view>

namespace rocklab {

struct LinearProps {
  double kn = 0;        ///< normal stiffness [N/m]
  double ks = 0;        ///< shear stiffness [N/m]
  double fric = 0;      ///< friction coefficient mu [-]
  double rgap = 0;      ///< reference gap g_r [m]
  int lin_mode = 0;     ///< normal-force update: 0 absolute, 1 incremental
  double dp_nratio = 0; ///< normal critical damping ratio beta_n [-], [0, 1]
  double dp_sratio = 0; ///< shear critical damping ratio beta_s [-], [0, 1]
  int dp_mode = 0;      ///< 0 full; 1 no-tension normal; 2 slip-cut shear; 3 both
  double emod = 0;      ///< effective modulus E* [Pa], > 0 selects the deformability method
  double kratio = 0;    ///< normal-to-shear stiffness ratio kappa* [-] (deformability method)
  double user_area = 0; ///< constant area for deformability [m^2], 0 = from the radii
};

/// The per-contact copy of what the update needs (kn, ks set by deformability at creation).
struct LinearParams {
  double kn = 0;        ///< normal stiffness [N/m]
  double ks = 0;        ///< shear stiffness [N/m]
  double fric = 0;      ///< friction coefficient [-]
  double rgap = 0;      ///< reference gap [m]
  double dp_nratio = 0; ///< normal critical damping ratio [-]
  double dp_sratio = 0; ///< shear critical damping ratio [-]
  std::uint8_t lin_mode = 0;
  std::uint8_t dp_mode = 0;
};

struct LinearState {
  double Fn = 0;        ///< linear normal force, > 0 tension [N]
  double Fss = 0;       ///< linear shear force along s_c [N]
  double Fst = 0;       ///< linear shear force along t_c [N]
  double E_slip = 0;    ///< accumulated slip dissipation [J]
  double E_dashpot = 0; ///< accumulated dashpot dissipation [J]
  bool slip = false;
};

struct LinearContact {
  LinearParams p;
  LinearState s;
};

namespace linear {

/// The contact area of the deformability method for a grain of radius r [m]: a strip 2r of unit
/// thickness in 2D, a disk pi r^2 in 3D [m^2 per m in 2D, m^2 in 3D].
inline double deformability_area(int dim, double r) {
  return dim == 2 ? 2.0 * r : std::numbers::pi * r * r;
}

/// Per-contact parameters from the assigned properties. With E* > 0 the deformability method sets
/// kn = A E* / L, ks = kn / kappa* (kappa* = 0 gives ks = 0), A = 2 r (2D, unit thickness) or
/// pi r^2 (3D), r = min(R1, R2) (R1 for ball-facet), L = R1 + R2 (R1 for ball-facet); the same
/// construction as the pbond's Eq. 16.
LinearParams make_params(const LinearProps& p, const CreationInfo& ci);

/// Update of the linear component only, written so bonded models can reuse it:
/// returns the linear force in `s` and accumulates slip energy. `slip_allowed` is false for
/// models that suppress slip while bonded.
void update_linear_part(const LinearParams& p, LinearState& s, const ContactKinematics& k,
                        EventSink& events, bool slip_allowed = true) noexcept;

/// The Coulomb shear spring of a point contact (also used by the impact models): incremental
/// ks, limit mu |Fn| (Fn <= 0 in compression), slip energy, slip_change events.
void shear_update(double ks, double fric, double Fn, double& Fss, double& Fst, double& E_slip,
                  bool& slip, const ContactKinematics& k, EventSink& events,
                  bool slip_allowed = true) noexcept;

/// The linear properties of a contact_models entry (kn/ks or emod/kratio, fric, rgap, lin_mode,
/// dashpots); the bonded models built on the linear component read theirs the same way.
LinearProps read_props(JsonObject& p, bool kn_required);

/// The linear component's state as results.json shows it (SI units).
nlohmann::json state_json(const LinearParams& p, const LinearState& s);

} // namespace linear

/// The linear model (PFC `linear`): traits for the registry (contact_model.hpp).
struct Linear {
  static constexpr std::string_view name = "linear";
  using Props = LinearProps;
  using Contact = LinearContact;

  static Contact make(const Props& p, const CreationInfo& ci) {
    return Contact{linear::make_params(p, ci), {}};
  }
  /// Force-displacement update of the linear and dashpot components. `force_active` keeps the
  /// dashpots working while the gap is open (a bonded contact of a bonded model is active).
  static void update(Contact& c, const ContactKinematics& k, ContactResult& out, EventSink& events,
                     bool force_active = false) noexcept;
  static ContactStiffness stiffness(const Contact& c) { return {c.p.kn + c.p.ks, c.p.ks, 0.0}; }
  static ContactEnergy energy(const Contact& c) {
    ContactEnergy e;
    if (c.p.kn > 0)
      e.strain += 0.5 * c.s.Fn * c.s.Fn / c.p.kn;
    if (c.p.ks > 0)
      e.strain += 0.5 * (c.s.Fss * c.s.Fss + c.s.Fst * c.s.Fst) / c.p.ks;
    e.slip = c.s.E_slip;
    e.dashpot = c.s.E_dashpot;
    return e;
  }
  /// The linear model never holds a contact alive beyond the proximity margin.
  static bool keeps_alive(const Contact&) { return false; }
  /// Surface-property inheritance of the linear component (Eq. 18-19 applied to kn, ks, fric);
  /// the stiffnesses only when they are not set by deformability.
  static void inherit(Props& p, const SurfaceProps& a, const SurfaceProps& b) {
    if (p.emod <= 0) {
      inherit_series(p.kn, a.kn, b.kn);
      inherit_series(p.ks, a.ks, b.ks);
    }
    inherit_minimum(p.fric, a.fric, b.fric);
  }
  /// Settable properties: fric [-], kn [N/m], ks [N/m].
  static double* property(Contact& c, std::string_view name) {
    return name == "fric" ? &c.p.fric : name == "kn" ? &c.p.kn : name == "ks" ? &c.p.ks : nullptr;
  }
  static Props read(JsonObject& p, int /*dim*/) { return linear::read_props(p, true); }
  static nlohmann::json state_json(const Contact& c, int /*dim*/);

  template <class A> static void io(A& a, Props& p) {
    a(p.kn), a(p.ks), a(p.fric), a(p.rgap), a(p.lin_mode), a(p.dp_nratio), a(p.dp_sratio),
        a(p.dp_mode), a(p.emod), a(p.kratio), a(p.user_area);
  }
  template <class A> static void io(A& a, LinearParams& p) {
    a(p.kn), a(p.ks), a(p.fric), a(p.rgap), a(p.dp_nratio), a(p.dp_sratio), a(p.lin_mode),
        a(p.dp_mode);
  }
  template <class A> static void io(A& a, LinearState& s) {
    a(s.Fn), a(s.Fss), a(s.Fst), a(s.E_slip), a(s.E_dashpot), a(s.slip);
  }
  template <class A> static void io(A& a, Contact& c) { io(a, c.p), io(a, c.s); }
};

} // namespace rocklab
