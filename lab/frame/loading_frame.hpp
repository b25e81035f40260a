// The loading frame of the test machine, the machine loop: it measures the specimen, mounts the
// test's fixtures (platens, curved jaws or grips; confining walls: lab/frame/fixtures.hpp),
// drives them (seating, confining servo, constant-rate loading, unloading), reads force, strain
// and stress every step, keeps the records (history, fine samples, peak, confinement band,
// cracks) and applies the stop rules. A test (lab/protocols/) chooses the fixtures and says what
// the readings mean. Talks to the engine only through the Model's public API and its event
// stream. Units SI; stresses and strains compression positive.
#pragma once

#include "core/model.hpp"
#include "lab/ae_monitor.hpp"
#include "lab/crack_monitor.hpp"
#include "lab/frame/fixtures.hpp"
#include "lab/frame/geometry.hpp"
#include "lab/protocol.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

namespace rocklab {

class FrameTest;

/// Phases of a test, in order.
enum Phase : int { kConfine = 0, kSeat = 1, kLoad = 2, kUnload = 3, kDone = 4 };

/// A recorded point of the test (the measurement channels, SI, compression positive).
struct LabSample {
  std::int64_t step = 0;
  double time = 0;
  double axial_strain = 0;   ///< shortening (compression, Brazilian) or elongation (tension) [-]
  double lateral_strain = 0; ///< compression positive: bulging is negative [-]
  double axial_stress = 0;   ///< platen load / current area; Brazilian: 2F/(pi D t) [Pa]
  double lateral_stress = 0; ///< confining walls [Pa]
  double load = 0;           ///< the quantity whose peak ends the test [Pa]
  double force = 0;          ///< platen (grip) force [N], 2D per unit thickness
};

/// How a test wants the frame set up (its fixtures: FrameTest::actuator, FrameTest::confinement).
struct FrameSetup {
  bool diametral = false;       ///< a disk loaded across its diameter (y axis), else along the axis
  Phase first_phase = kSeat;    ///< kConfine, kSeat (platens close to the seating stress) or kLoad
  double reverse_at_strain = 0; ///< > 0: unload from this axial strain back to zero [-]
};

/// The peak of the load and the state at it.
struct PeakRecord {
  double load = 0, strain = 0, stress = 0, force = 0, lateral = 0, time = 0;
  std::int64_t step = -1, tension = 0, shear = 0; ///< step and crack counts at the peak
  /// At the peak, |F_top + F_bottom| / (|F_top| + |F_bottom|) of the platens (-1: grips).
  double imbalance = -1;
  template <class A> void fields(A& a) {
    a("load", load), a("strain", strain), a("stress", stress), a("force", force);
    a("lateral", lateral), a("time", time), a("step", step), a("tension", tension);
    a("shear", shear), a("imbalance", imbalance);
  }
};

/// The confining stress as a pressure gauge reads it: 100-step means (a few stress-wave transits
/// of a grain), so single-step spikes from breaking bonds do not count, beside the instantaneous
/// extremes.
struct ConfinementBand {
  static constexpr int kWindow = 100;
  double min = 0, max = 0, sum = 0;
  std::int64_t n = 0, win_n = 0;
  double win_sum = 0, inst_min = 0, inst_max = 0;
  bool seen = false;
  double peak_min = 0, peak_max = 0; ///< the band up to the peak

  void start(double stress);
  void add(double stress);
  nlohmann::json json(double confinement) const;
  template <class A> void fields(A& a) {
    a("min", min), a("max", max), a("sum", sum), a("n", n), a("win_n", win_n);
    a("win_sum", win_sum), a("inst_min", inst_min), a("inst_max", inst_max), a("seen", seen);
    a("peak_min", peak_min), a("peak_max", peak_max);
  }
};

class LoadingFrame {
public:
  /// The test's fixtures and options are taken from `test` (read with the protocol).
  LoadingFrame(const Protocol& p, FrameTest& test, Model& m, const nlohmann::json& meta);

  /// Measure the specimen, add the machine's walls and grips, start the first phase.
  void setup();
  /// One step: control, cycle, events, measurement, records, stop rules.
  void advance();
  bool done() const { return phase_ == kDone; }
  /// Everything a continued run depends on, and its restoration (the model is restored apart).
  nlohmann::json state() const;
  void restore(const nlohmann::json& state, const std::string& file);
  /// results.json: the frame's part and the protocol's.
  nlohmann::json results() const;
  void write_history_csv(std::ostream& out) const;

  // What protocols read.
  const Protocol& protocol() const { return p_; }
  const Model& model() const { return m_; }
  const SpecimenGeometry& geometry() const { return geo_; }
  const CrackMonitor& cracks() const { return monitor_; }
  /// The acoustic-emission events and their sources, formed while the test runs.
  const AeMonitor& acoustic_emission() const { return ae_; }
  const std::vector<LabSample>& samples() const { return samples_; }
  const LabSample& current() const { return current_; }
  const PeakRecord& peak() const { return peak_; }
  double load_ref() const { return load_ref_; } ///< load when loading began [Pa]
  /// The change of every energy term since loading began (since the test began before it) [J].
  EnergyLedger energy_since_loading() const;
  double sep_ref() const { return sep_ref_; } ///< separation when loading began [m]
  double separation() const;                  ///< platen or grip separation [m]
  std::int64_t load_start_step() const { return load_start_step_; }
  std::int64_t reverse_step() const { return reverse_step_; }
  bool confined() const { return confinement_ != nullptr; }
  /// The confining walls' stress [Pa] (0: not confined).
  double confining_stress() const { return confinement_ ? confinement_->target() : 0.0; }
  const FrameSetup& frame_setup() const { return setup_; }
  const ConfinementBand& confinement_band() const { return band_; }
  bool loading() const { return phase_ >= kLoad; }
  /// While loading, the platens close again with the seating servo to the seating stress, then
  /// load on at the test's rate after the usual ramp; the peak and the curve so far stand. A test
  /// asks for it when the platens lost the specimen (lab/protocols/brazilian_reseating.hpp).
  /// False where it cannot: grips, not loading, or already seating again.
  bool seat_again();
  bool seating_again() const { return seating_again_; }
  /// The current cross-section [m^2] (confined: the walls'; else widened by the lateral strain).
  double current_area(double lateral_strain) const;
  /// The specimen's volume now [m^3] (2D: area x unit thickness): the current section times the
  /// actuators' separation; a diametral disk keeps its initial volume.
  double current_volume() const;

  // What the run loop reads.
  bool snapshot_due() const { return snapshot_due_; }
  void snapshot_taken() { snapshot_due_ = false; }
  bool peak_snapshot_due() const { return peak_snap_due_; }
  void peak_snapshot_taken() { peak_snap_due_ = false; }
  const char* phase_name() const;
  const std::vector<Vec3>& reference_positions() const { return reference_; }

private:
  // setup.cpp
  void measure_specimen(const std::string& shape, bool diametral);
  void check_reachable_strain() const;
  LinearProps wall_contact() const;
  void find_shell();
  // measure.cpp
  void measure(LabSample& s) const;
  double wall_height() const; ///< the confining walls' height: the platens' separation
  double lateral_strain() const;
  double shell_strain() const;
  // control.cpp
  void control();
  /// The loading speed's factor for loading.approach_stress: approach_rate below it, easing to 1
  /// over ramp_steps once it is reached, 1 without an approach.
  double approach_factor() const;
  // loading_frame.cpp
  void record_history();
  void mark_energy_start();
  void energy_results(nlohmann::json& r) const;
  void quasi_static_results(nlohmann::json& r) const;
  void begin_loading();
  bool servoed_to(double target, double tol, std::int64_t since) const;
  void finish(const std::string& why);
  void track_peak();
  bool stop_rules();
  template <class A> void fields(A& a);

  const Protocol& p_;
  FrameTest& test_;
  Model& m_;
  const nlohmann::json& meta_;
  FrameSetup setup_;
  SpecimenGeometry geo_;
  // fixtures and gauges
  std::unique_ptr<Actuator> actuator_;          ///< platens, jaws or grips
  std::unique_ptr<ConfiningWalls> confinement_; ///< the test's confining walls, if any
  std::vector<std::int32_t> shell_; ///< lateral-surface grains (the unconfined lateral gauge)
  // state
  int phase_ = kSeat;
  std::int64_t phase_start_step_ = 0, load_start_step_ = 0, reverse_step_ = -1;
  std::int64_t ramp_start_step_ = 0; ///< the loading ramp's start (loading, or a re-seating's end)
  std::int64_t approach_end_step_ = -1; ///< the step the approach stress was reached (-1: not yet)
  bool seating_again_ = false;          ///< closing again to the seating stress while loading
  std::int64_t seat_again_step_ = 0;    ///< the step the last seating again began
  double v_final_ = 0;                  ///< platen (grip) speed while loading [m/s]
  double sep_ref_ = 0;                  ///< platen or grip separation when loading began [m]
  std::vector<Vec3> shell_ref_;
  double load_ref_ = 0;         ///< load when loading began (the seating stress)
  std::vector<Vec3> reference_; ///< grain positions when the test began
  PeakRecord peak_;
  DensityScaling density_; ///< what the density scaling did at the start of loading
  ConfinementBand band_;
  std::vector<double> wall_k_; ///< stiffness sum of each wall's contacts (servo gains, reused)
  std::int64_t bond_break_events_ = 0; ///< bond_break events seen (each becomes a crack)
  double next_snapshot_strain_ = 0;
  bool snapshot_due_ = false, peak_snap_due_ = false;
  std::int64_t peak_snap_step_ = -1;
  std::string stop_reason_;
  LabSample current_;
  std::vector<LabSample> samples_;           ///< fine record of the loading (fits)
  std::vector<std::vector<double>> history_; ///< measurements, then the raw energy ledger
  /// The energy ledger's terms (EnergyLedger::terms) when the test began and when loading began:
  /// history.csv and results.json count energies from these.
  std::vector<double> energy_start_, energy_load_;
  CrackMonitor monitor_;
  AeMonitor ae_;
  std::vector<Event> events_;
};

} // namespace rocklab
