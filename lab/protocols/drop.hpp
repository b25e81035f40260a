// Drop (impact) test of the rock-impact thesis (chapters 5-6): a rock (a clump of pebbles or a
// single ball) hits a rigid platen normally at one or many speeds; the normal restitution is
// measured by velocity and by energy (Eq. 24), with the energy lost to plastic work, friction,
// damping and bond breakage. Optionally the exponent b of the elastic-perfectly-plastic power
// function is fitted per speed so the rebound follows the RocFall scaling law (Eq. 35).
// Protocol keys: docs/protocol-format.md ("Drop test"). Units SI.
#pragma once

#include "contact/registry.hpp"
#include "core/clumps.hpp"
#include "io/work_estimate.hpp"

#include <nlohmann/json.hpp>

#include <atomic>
#include <string>
#include <vector>

namespace rocklab {

struct DropProtocol {
  std::string file;
  int dim = 2;
  std::vector<Pebble> rock; ///< pebbles, rock at the origin
  /// A bonded rock: the pebbles are separate balls joined by this bonded model (contactbond or
  /// linearpbond, bonded where they touch) and can break into fragments; otherwise one clump.
  bool bonded = false;
  std::string bond_model;
  ModelProps bond;
  double density = 2600; ///< [kg/m^3]
  std::string model;     ///< rock-platen contact model name
  ModelProps contact;
  std::vector<double> speeds; ///< impact speeds [m/s]
  double gravity = 9.81;      ///< [m/s^2], acting against the platen normal
  double release_gap = 0;     ///< lowest rock point above the platen at release [m]
  double timestep_safety = 0.1;
  double local_damping = 0;
  double max_time = 1.0; ///< per drop, after release [s]
  std::int64_t history_every = 20;
  // calibration (Eq. 35)
  bool calibrate = false;
  double R_N = 0.53;     ///< unscaled normal restitution coefficient [-]
  double V_half = 9.144; ///< speed at which the scaling factor is 0.5 [m/s]
  double b_min = 1, b_max = 500;
  double tolerance = 1e-3; ///< relative, on the restitution
  bool plots = true;
  nlohmann::json raw;
};

/// RocFall scaled restitution (thesis Eq. 35): R_N / (1 + (v / V_half)^2).
double rocfall_restitution(double R_N, double V_half, double v);

struct DropResult {
  double speed = 0;        ///< requested impact speed [m/s]
  double v_impact = 0;     ///< measured normal speed just before the first touch [m/s]
  double v_rebound = 0;    ///< normal velocity when the rock left the platen [m/s]
  double v_tangential = 0; ///< tangential speed of the centroid after the rebound [m/s]
  double spin = 0;         ///< angular speed after the rebound [rad/s]
  double e_velocity = 0;   ///< v_rebound / v_impact
  double e_energy = 0;     ///< sqrt(KE after / KE before), translation + rotation (Eq. 24)
  double ke_before = 0, ke_after = 0, ke_rotational_after = 0; ///< [J]
  double plastic = 0, slip = 0, dashpot = 0, damping = 0,
         bond_break = 0;         ///< lost in the impact [J]
  double contact_time = 0;       ///< from first touch to leaving [s]
  double max_force = 0;          ///< largest platen force [N]
  int touches = 0;               ///< contact episodes before leaving (rocking clumps touch again)
  int bonds_broken = 0;          ///< bonded rock: bonds broken in the drop
  std::vector<double> fragments; ///< bonded rock: fragment masses at the end, largest first [kg]
  bool rebounded = false;        ///< false: the rock stayed on the platen within max_time
  double exponent = 0;           ///< b used (powerplastic)
  double target = 0;             ///< Eq. 35 restitution at this speed (calibration)
  std::int64_t steps = 0;
};

DropProtocol drop_protocol_from_json(const nlohmann::json& j, const std::string& file);

/// One drop at `speed` with the protocol's contact (exponent b overrides pp_b when > 0).
/// Appends history rows (speed, time, energies of the rock) to `history` if given.
DropResult run_drop(const DropProtocol& p, double speed, double exponent = 0,
                    std::string* history = nullptr);

/// What the protocol asks for: every drop to max_time at its model's time step (upper bound).
WorkEstimate drop_estimate(const DropProtocol& p);

/// Run the protocol (all speeds, calibration if asked) and write OUT/results.json,
/// restitution.csv, history.csv and restitution.svg (+ exponent.svg). Returns results.json.
nlohmann::json run_drop_test(const DropProtocol& p, const std::string& out_dir, bool progress,
                             const std::atomic<bool>* interrupt);

} // namespace rocklab
