// Interface between the engine and contact models. A contact model is plain data (properties and
// per-contact state) plus pure functions; the engine hands it the kinematics of the step, the model
// returns force and moment in contact-plane coordinates. No I/O, no access to the model.
#pragma once

#include "core/events.hpp"
#include "core/types.hpp"

namespace rocklab {

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

} // namespace rocklab
