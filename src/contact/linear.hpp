// Linear contact model (PFC `linear`): linear springs with Coulomb slip and optional dashpots.
// The linear component is also the first interface of the linear parallel bond model
// (linear-parallel-bond-model.md, Eq. 1), where the formulation is referenced.
#pragma once

#include "contact/contact_model.hpp"

#include <cstdint>

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

/// Per-contact parameters from the assigned properties. With E* > 0 the deformability method sets
/// kn = A E* / L, ks = kn / kappa* (kappa* = 0 gives ks = 0), A = 2 r (2D, unit thickness) or
/// pi r^2 (3D), r = min(R1, R2) (R1 for ball-facet), L = R1 + R2 (R1 for ball-facet); the same
/// construction as the pbond's Eq. 16.
LinearParams make_params(const LinearProps& p, int dim, double R1, double R2, bool ball_facet);

/// Force-displacement update of the linear and dashpot components. `force_active` keeps the
/// dashpots working while the gap is open (a bonded contact of a bonded model is active).
void update(LinearContact& c, const ContactKinematics& k, ContactResult& out, EventSink& events,
            bool force_active = false) noexcept;

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

inline ContactStiffness stiffness(const LinearContact& c) {
  return {c.p.kn + c.p.ks, c.p.ks, 0.0};
}

inline ContactEnergy energy(const LinearContact& c) {
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
inline bool keeps_alive(const LinearContact&) {
  return false;
}

} // namespace linear
} // namespace rocklab
