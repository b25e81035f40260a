// Acoustic-emission sources followed while they happen (Hazzard & Young 2000, 2004): each crack
// joins an open event whose source grains it shares or touches, or opens one; while an event is
// open its moment tensor is summed every step from the contact forces its source grains exert on
// their neighbours, M_ij = sum dF_i R_j (dF the change since the grain joined the source, R from
// the event's crack centroid to the contact point), and kept at its largest scalar moment.
// docs/protocol-format.md ("Acoustic emission") states the choices the papers leave open. Units
// SI: tensors in N m (2D: per metre of the unit thickness), times in s.
#pragma once

#include "core/model.hpp"
#include "lab/crack_monitor.hpp"
#include "lab/moment_tensor.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <vector>

namespace rocklab {

/// One event's source, as followed.
struct AeSource {
  Mat3 tensor = Mat3::Zero(); ///< moment tensor at its largest scalar moment [N m]
  double m0 = 0;              ///< that scalar moment [N m]
  double time_of_max = 0;     ///< when it was reached [s]
  double end = 0;             ///< when the event closed (its last crack's duration ran out) [s]
  int grains = 0;             ///< source grains (the grains of its cracks) [-]
};

class AeMonitor {
public:
  /// Each crack keeps its event open this long [s]; 0 (default): Hazzard & Young's duration, the
  /// time a rupture at half the shear-wave speed takes to cross the crack's larger grain.
  void set_duration(double seconds) { fixed_duration_ = seconds; }
  /// After each step: the cracks recorded since the last call (`cracks` is the monitor's whole
  /// list, in time order) join or open events, and the open events' tensors are summed from the
  /// model's contact forces. `volume` [m^3] (2D: the area times the unit thickness) serves the
  /// shear-wave speed estimate, made at the first crack.
  void step(const Model& m, const std::vector<Crack>& cracks, double volume);
  /// Close every open event at `time` [s] (the test ended).
  void finish(double time);
  /// Whether moment tensors are summed (default); without them events are still formed.
  void set_tensors(bool on) { tensors_ = on; }
  /// The event of each crack (index = crack record), event ids from 0 in order of first crack.
  const std::vector<int>& event_of_crack() const { return event_of_crack_; }
  /// The sources by event id (an open event's as followed so far).
  std::vector<AeSource> sources() const;
  /// The shear-wave speed the durations use [m/s] (0 before the first crack).
  double shear_wave_speed() const { return v_s_; }
  double fixed_duration() const { return fixed_duration_; }
  nlohmann::json to_json() const; ///< for checkpoints
  void from_json(const nlohmann::json& j);

private:
  struct Open {
    int event = 0;
    double end = 0;                   ///< closes after this time [s]
    std::vector<std::int32_t> grains; ///< source grains (ball indices)
    Mat3 a0 = Mat3::Zero(), a = Mat3::Zero(), a_before = Mat3::Zero(); ///< sum F x^T [N m]
    Vec3 f0 = Vec3::Zero(), f = Vec3::Zero(), f_before = Vec3::Zero(); ///< sum F [N]
    Vec3 crack_sum = Vec3::Zero(); ///< sum of its cracks' positions [m]
    int cracks = 0;
    bool changed = false;
  };
  void sum_forces(const Model& m);
  void build_partners(const Model& m);
  void assign(const Model& m, const Crack& c);
  void follow(double time);
  void close_ended(double time);
  double duration(const Model& m, std::int32_t g1, std::int32_t g2) const;

  double fixed_duration_ = 0;
  bool tensors_ = true;
  double v_s_ = 0;
  std::size_t seen_ = 0; ///< crack records taken so far
  std::vector<int> event_of_crack_;
  std::vector<AeSource> sources_; ///< by event id
  std::vector<Open> open_;
  std::vector<int> slot_;   ///< event id -> index into open_, -1 when closed
  std::vector<int> source_; ///< ball index -> open event id it is a source grain of, or -1
  std::vector<std::int32_t> partner_begin_, partners_; ///< grains touching each grain (CSR)
  std::vector<std::int32_t> partner_fill_;             ///< scratch of build_partners
};

/// The shear-wave speed sqrt(G / rho) of the packing [m/s]: G the affine (uniform-strain, Voigt)
/// shear modulus of its grain-grain contacts' stiffnesses over `volume`, averaged over the
/// coordinate planes, rho the grains' mass over `volume`. 0 without contacts.
double affine_shear_wave_speed(const Model& m, double volume);

} // namespace rocklab
