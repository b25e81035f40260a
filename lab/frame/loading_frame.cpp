// The loading frame's step, records and stop rules, its state for checkpoints and the common part
// of results.json.
#include "lab/frame/loading_frame.hpp"

#include "io/json_fields.hpp"
#include "io/results.hpp"
#include "lab/frame/frame_test.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <ostream>
#include <stdexcept>

namespace rocklab {

void ConfinementBand::start(double stress) {
  min = max = inst_min = inst_max = stress;
  peak_min = peak_max = stress;
  seen = false;
  win_sum = 0;
  win_n = 0;
}

void ConfinementBand::add(double stress) {
  sum += stress;
  ++n;
  win_sum += stress;
  if (++win_n == kWindow) {
    const double mean = win_sum / kWindow;
    min = seen ? std::min(min, mean) : mean;
    max = seen ? std::max(max, mean) : mean;
    seen = true;
    win_sum = 0;
    win_n = 0;
  }
  inst_min = std::min(inst_min, stress);
  inst_max = std::max(inst_max, stress);
}

nlohmann::json ConfinementBand::json(double) const {
  return {{"mean", n ? sum / static_cast<double>(n) : 0.0},
          {"min", min},
          {"max", max},
          {"averaging_steps", kWindow},
          {"before_peak_min", peak_min},
          {"before_peak_max", peak_max},
          {"instantaneous_min", inst_min},
          {"instantaneous_max", inst_max}};
}

namespace {

constexpr std::size_t kMeasured = 13; // history columns before the energy ledger

std::vector<double> ledger_values(EnergyLedger e) {
  std::vector<double> v;
  e.terms([&](double& x) { v.push_back(x); });
  return v;
}

EnergyLedger ledger_from(const double* v) {
  EnergyLedger e;
  int i = 0;
  e.terms([&](double& x) { x = v[i++]; });
  return e;
}

} // namespace

void LoadingFrame::mark_energy_start() {
  energy_start_ = ledger_values(m_.energy());
}

EnergyLedger LoadingFrame::energy_since_loading() const {
  const std::vector<double>& ref = energy_load_.empty() ? energy_start_ : energy_load_;
  if (ref.size() != EnergyLedger::kTerms)
    return m_.energy();
  return m_.energy().since(ledger_from(ref.data()));
}

const char* LoadingFrame::phase_name() const {
  static const char* names[] = {"confining", "seating", "loading", "unloading", "done"};
  return names[phase_];
}

void LoadingFrame::begin_loading() {
  if (p_.timestep_safety > 0)
    m_.settings.timestep_safety = p_.timestep_safety;
  if (p_.density_scaling > 0)
    density_ = m_.scale_density(p_.density_scaling);
  phase_ = kLoad;
  load_start_step_ = phase_start_step_ = ramp_start_step_ = m_.step();
  energy_load_ = ledger_values(m_.energy());
  sep_ref_ = separation();
  shell_ref_.clear();
  for (std::int32_t i : shell_)
    shell_ref_.push_back(m_.balls.pos[static_cast<std::size_t>(i)]);
  if (confinement_)
    confinement_->mark_reference(m_, geo_);
  LabSample s;
  measure(s);
  load_ref_ = s.load;
  band_.start(s.lateral_stress);
  next_snapshot_strain_ = p_.vtk_every_strain;
  snapshot_due_ = p_.vtk; // the start of loading
}

void LoadingFrame::record_history() {
  const LabSample& s = current_;
  const double vol =
      s.axial_strain + (geo_.dim == 2 ? 1.0 : 2.0) * s.lateral_strain; // compression positive
  std::vector<double> row{s.time,
                          static_cast<double>(s.step),
                          static_cast<double>(phase_),
                          s.axial_strain,
                          s.lateral_strain,
                          vol,
                          s.axial_stress,
                          s.lateral_stress,
                          s.load,
                          s.force,
                          static_cast<double>(monitor_.tension()),
                          static_cast<double>(monitor_.shear()),
                          static_cast<double>(monitor_.total())};
  const std::vector<double> e = ledger_values(m_.energy());
  row.insert(row.end(), e.begin(), e.end());
  history_.push_back(std::move(row));
}

void LoadingFrame::write_history_csv(std::ostream& out) const {
  // Energies count from the start of loading; rows before it (confining, seating) from the start
  // of the test.
  out << "time_s,step,phase,axial_strain,lateral_strain,volumetric_strain,axial_stress_Pa,"
         "lateral_stress_Pa,deviator_Pa,force_N,cracks_tension,cracks_shear,"
         "cracks_total,kinetic_J,strain_J,bond_strain_J,slip_J,local_damping_J,"
         "dashpot_J,plastic_J,bond_break_J,body_work_J,boundary_work_J,"
         "balance_error_J\n";
  const EnergyLedger start = energy_start_.size() == EnergyLedger::kTerms
                                 ? ledger_from(energy_start_.data())
                                 : EnergyLedger{};
  const EnergyLedger load =
      energy_load_.size() == EnergyLedger::kTerms ? ledger_from(energy_load_.data()) : start;
  std::string s; // one row at a time
  for (const auto& row : history_) {
    s.clear();
    for (std::size_t k = 0; k < kMeasured; ++k) {
      if (k)
        s += ',';
      s += (k == 1 || k == 2 || k >= 10) ? std::to_string(std::llround(row[k]))
                                         : format_double(row[k]);
    }
    const EnergyLedger e = ledger_from(row.data() + kMeasured)
                               .since(row[2] < static_cast<double>(kLoad) ? start : load);
    for (double v : {e.kinetic(), e.strain, e.bond_strain, e.slip, e.local_damping, e.dashpot,
                     e.plastic, e.bond_break, e.body_work, e.boundary_work, e.balance_error()})
      s += ',' + format_double(v);
    s += '\n';
    out << s;
  }
}

void LoadingFrame::finish(const std::string& why) {
  stop_reason_ = why;
  phase_ = kDone;
  ae_.finish(m_.time());
  for (Wall& w : m_.walls) {
    w.velocity.setZero();
    w.radial_velocity = 0;
  }
  if (history_.empty() || static_cast<std::int64_t>(history_.back()[1]) != m_.step())
    record_history();
}

void LoadingFrame::advance() {
  control();
  m_.cycle(1);
  events_.clear();
  m_.drain_events(events_);
  for (const Event& ev : events_)
    bond_break_events_ += ev.type == EventType::BondBreak ? 1 : 0;
  monitor_.consume(m_, events_);
  ae_.step(m_, monitor_.cracks(), current_volume());
  measure(current_);
  const std::int64_t since = m_.step() - phase_start_step_;
  if (phase_ == kConfine || phase_ == kSeat) {
    // The platens (and confining walls) servo to their stress; loading begins once every wall is
    // within its band and the specimen is at rest.
    const double target = phase_ == kConfine ? confining_stress() : p_.seating_stress;
    const double tol = phase_ == kConfine ? confinement_->tolerance() : 0.1;
    if (servoed_to(target, tol, since)) {
      record_history();
      begin_loading();
    } else if (since > p_.max_steps) {
      throw InputError(p_.file + ": the " + phase_name() + " phase did not reach its stress in " +
                       std::to_string(p_.max_steps) + " steps (key 'stop.max_steps')");
    }
    if (since % p_.history_every == 0)
      record_history();
    return;
  }
  // Loading or unloading.
  if (seating_again_ && servoed_to(p_.seating_stress, 0.1, m_.step() - seat_again_step_)) {
    seating_again_ = false; // seated again (as the seating phase): load on after the ramp
    ramp_start_step_ = m_.step();
  }
  if (approach_end_step_ < 0 && p_.approach_stress > 0 &&
      current_.axial_stress >= p_.approach_stress)
    approach_end_step_ = m_.step(); // the approach ends: the platens slow to the loading rate
  const std::int64_t loading = m_.step() - load_start_step_;
  const std::int64_t fine = std::max<std::int64_t>(1, p_.history_every / 10);
  if (loading % fine == 0) {
    samples_.push_back(current_);
    test_.sampled(*this, current_);
  }
  if (confinement_)
    band_.add(current_.lateral_stress);
  track_peak();
  if (p_.vtk && p_.vtk_every_strain > 0 && phase_ == kLoad &&
      current_.axial_strain >= next_snapshot_strain_) {
    snapshot_due_ = true;
    while (next_snapshot_strain_ <= current_.axial_strain)
      next_snapshot_strain_ += p_.vtk_every_strain;
  }
  if (loading % p_.history_every == 0)
    record_history();
  stop_rules();
}

// The seating (and confining) phase's rule, also for the end of a re-seating: checked every 100
// steps from step 200 of the phase on, every wall within tol of its target and the grains at rest.
bool LoadingFrame::servoed_to(double target, double tol, std::int64_t since) const {
  if (since % 100 != 0 || since < 200)
    return false;
  const bool ok = std::abs(current_.axial_stress - target) <= tol * target &&
                  (!confinement_ || confinement_->within(m_, geo_, wall_height(), target, tol));
  return ok && m_.mean_unbalanced_force_ratio() <= 1e-2;
}

bool LoadingFrame::seat_again() {
  if (actuator_->wall() < 0 || phase_ != kLoad || seating_again_)
    return false;
  seating_again_ = true;
  seat_again_step_ = m_.step();
  record_history();
  return true;
}

void LoadingFrame::track_peak() {
  if (phase_ != kLoad || current_.load <= peak_.load)
    return;
  peak_ = {current_.load,  current_.axial_strain,   current_.axial_stress,
           current_.force, current_.lateral_strain, current_.time,
           current_.step,  monitor_.tension(),      monitor_.shear()};
  peak_.imbalance = actuator_->imbalance(m_, geo_.axis);
  band_.peak_min = band_.min;
  band_.peak_max = band_.max;
  if (p_.vtk && m_.step() - peak_snap_step_ >= p_.history_every) {
    peak_snap_due_ = true; // the caller copies a snapshot (throttled)
    peak_snap_step_ = m_.step();
  }
}

bool LoadingFrame::stop_rules() {
  const std::int64_t loading = m_.step() - load_start_step_;
  if (phase_ == kLoad && setup_.reverse_at_strain > 0 &&
      current_.axial_strain >= setup_.reverse_at_strain) {
    phase_ = kUnload;
    reverse_step_ = m_.step();
    record_history();
    return false;
  }
  if (phase_ == kUnload) {
    if (current_.axial_strain <= 0 || current_.load <= load_ref_)
      finish("unloaded to the start");
    else if (loading > p_.max_steps)
      finish("stop.max_steps reached");
    return done();
  }
  const bool dropped = loading >= p_.min_steps && peak_.load > load_ref_ &&
                       current_.load < p_.post_peak_fraction * peak_.load;
  if (dropped) {
    // The test decides whether the drop ends it (a Brazilian disk must have split first).
    const std::string why = test_.stop_after_drop(*this);
    if (!why.empty())
      finish(why);
    else if (loading > p_.max_steps)
      finish("stop.max_steps reached");
  } else if (const std::string why = loading >= p_.min_steps && phase_ == kLoad
                                         ? test_.stop_while_loading(*this)
                                         : std::string();
             !why.empty()) {
    finish(why);
  } else if (p_.strain_limit > 0 && current_.axial_strain >= p_.strain_limit) {
    finish("stop.strain_limit reached");
  } else if (loading > p_.max_steps) {
    finish("stop.max_steps reached");
  }
  return done();
}

template <class A> void LoadingFrame::fields(A& a) {
  a.object("geometry", geo_);
  a("phase", phase_), a("phase_start_step", phase_start_step_);
  a("load_start_step", load_start_step_), a("reverse_step", reverse_step_);
  a("ramp_start_step", ramp_start_step_), a("seating_again", seating_again_);
  a("seat_again_step", seat_again_step_);
  if (confinement_)
    confinement_->fields(a); // the fixture's fields; the actuator's: state(), restore()
  a("shell", shell_), a("v_final", v_final_), a("sep_ref", sep_ref_), a("shell_ref", shell_ref_);
  a("load_ref", load_ref_), a("reference", reference_);
  a.object("peak", peak_);
  if (p_.density_scaling > 0) // (checkpoints of runs without it keep their old fields)
    a.object("density_scaling", density_);
  if (p_.approach_stress > 0)
    a("approach_end_step", approach_end_step_);
  a.object("confinement_band", band_);
  a("bond_break_events", bond_break_events_);
  a("next_snapshot_strain", next_snapshot_strain_), a("snapshot_due", snapshot_due_);
  a("peak_snap_step", peak_snap_step_), a("stop_reason", stop_reason_), a("history", history_);
  a("energy_start", energy_start_), a("energy_load", energy_load_);
}

nlohmann::json LoadingFrame::state() const {
  nlohmann::json s = nlohmann::json::object();
  JsonFieldWriter w{s};
  const_cast<LoadingFrame*>(this)->fields(w); // the writer only reads
  actuator_->save(s);
  nlohmann::json samples = nlohmann::json::array();
  for (const LabSample& x : samples_)
    samples.push_back({x.step, x.time, x.axial_strain, x.lateral_strain, x.axial_stress,
                       x.lateral_stress, x.load, x.force});
  s["samples"] = std::move(samples);
  s["cracks"] = monitor_.to_json();
  s["acoustic_emission"] = ae_.to_json();
  nlohmann::json own = nlohmann::json::object();
  test_.save(own);
  s["test"] = std::move(own);
  return s;
}

void LoadingFrame::restore(const nlohmann::json& s, const std::string& file) {
  JsonFieldReader r{s, file};
  fields(r);
  // Every index the state names must exist in the restored model.
  auto check = [&](bool ok, const char* what) {
    if (!ok)
      throw InputError(file + ": corrupt checkpoint (" + what + " out of range)");
  };
  const auto balls = static_cast<std::int32_t>(m_.balls.size());
  check(phase_ >= kConfine && phase_ <= kDone, "phase");
  actuator_->restore(s, file, m_);
  if (confinement_)
    confinement_->check(m_, file);
  else if (s.contains("lateral"))
    throw InputError(file + ": corrupt checkpoint (confining walls in an unconfined test's state)");
  for (std::int32_t i : shell_)
    check(i >= 0 && i < balls, "grain index");
  check(shell_ref_.empty() || shell_ref_.size() == shell_.size(), "lateral-surface grains");
  const nlohmann::json& samples = r.at("samples");
  try {
    samples_.clear();
    for (const auto& x : samples)
      samples_.push_back({x.at(0).get<std::int64_t>(), x.at(1).get<double>(), x.at(2).get<double>(),
                          x.at(3).get<double>(), x.at(4).get<double>(), x.at(5).get<double>(),
                          x.at(6).get<double>(), x.at(7).get<double>()});
    monitor_.from_json(r.at("cracks"));
    ae_.from_json(r.at("acoustic_emission"));
  } catch (const nlohmann::json::exception&) {
    throw InputError(file + ": corrupt checkpoint (samples, cracks or acoustic emission)");
  }
  test_.load(r.at("test"), file);
  m_.settings.slip_events = false;
  measure(current_);
}

// The energy ledger of the test, counted from the start of loading, and its balance (warned when
// it does not close to 1 % of the energy turned over).
void LoadingFrame::energy_results(nlohmann::json& r) const {
  const EnergyLedger e = energy_since_loading();
  nlohmann::json j = energy_json(e);
  const double scale = e.balance_scale();
  const double rel = scale > 0 ? e.balance_error() / scale : 0.0;
  j.erase("initial_total");
  j["counted_from"] = "the start of loading (step " + std::to_string(load_start_step_) + ")";
  j["balance_error_relative"] = rel;
  j["units"] = "J (2D: per metre of thickness)";
  r["energy_J"] = j;
  if (!(std::abs(rel) <= 0.01))
    r["warnings"].push_back("the energy ledger of the loading does not close: balance error " +
                            format_double(e.balance_error()) + " J, " + format_double(100 * rel) +
                            " % of the energy turned over");
}

// Whether the test was quasi-static at its peak. In a quasi-static test both platens carry the
// same force and the grains' kinetic energy is a small part of what the specimen stores; a rate
// far above the quasi-static one (issue 16: a UCS at 99.9/s read a peak of 7.2 MPa against 1.3)
// shows in both. Limits: 5 % platen imbalance, kinetic energy 1 % of the stored energy (the
// presets' UCS at the default rate: docs/results.md, "Loading rate").
void LoadingFrame::quasi_static_results(nlohmann::json& r) const {
  constexpr double kImbalance = 0.05, kKinetic = 0.01;
  double kinetic_ratio = 0; // from the last history row up to the peak (every history_every)
  for (const std::vector<double>& row : history_) {
    if (row[1] > static_cast<double>(peak_.step))
      break;
    const EnergyLedger e = ledger_from(row.data() + kMeasured);
    kinetic_ratio = e.stored() > 0 ? e.kinetic() / e.stored() : 0.0;
  }
  nlohmann::json q = {
      {"kinetic_over_stored_energy_at_peak", kinetic_ratio},
      {"limits",
       {{"platen_force_imbalance", kImbalance}, {"kinetic_over_stored_energy", kKinetic}}}};
  q["platen_force_imbalance_at_peak"] =
      peak_.imbalance >= 0 ? nlohmann::json(peak_.imbalance) : nlohmann::json(nullptr);
  const bool ok = peak_.imbalance <= kImbalance && kinetic_ratio <= kKinetic;
  q["ok"] = ok;
  r["quasi_static"] = q;
  if (!ok)
    r["warnings"].push_back(
        "the test was not quasi-static at its peak (platen force imbalance " +
        (peak_.imbalance >= 0 ? format_double(peak_.imbalance) : std::string("-")) +
        ", kinetic / stored energy " + format_double(kinetic_ratio) + "; limits " +
        format_double(kImbalance) + " and " + format_double(kKinetic) +
        "): lower loading.strain_rate; the strengths and moduli are those of a dynamic test");
}

nlohmann::json LoadingFrame::results() const {
  nlohmann::json r;
  r["units"] = "SI (m, kg, s, N, Pa, J); stresses and strains compression positive";
  r["test"] = test_.name();
  r["stop_reason"] = stop_reason_;
  const std::int64_t top = actuator_->wall();
  for (const ModelRule& rule : m_.rules) // the platens' friction, as the model has it
    if (top >= 0 && rule.wall == top && std::holds_alternative<LinearProps>(rule.props))
      r["platen_friction"] = std::get<LinearProps>(rule.props).fric;
  const double crack_area = [&] {
    double a = 0;
    for (const Crack& c : monitor_.cracks())
      a += geo_.dim == 2 ? c.size : 0.25 * std::numbers::pi * c.size * c.size;
    return a;
  }();
  r["cracks"] = {{"tension", monitor_.tension()},
                 {"shear", monitor_.shear()},
                 {"total", monitor_.total()},
                 {"at_peak",
                  {{"tension", peak_.tension},
                   {"shear", peak_.shear},
                   {"total", peak_.tension + peak_.shear}}},
                 {"density_per_m3", static_cast<double>(monitor_.total()) / geo_.volume},
                 {"area_per_volume_per_m", crack_area / geo_.volume}};
  r["bond_break_events"] = bond_break_events_;
  r["load_start_step"] = load_start_step_;
  r["peak_step"] = peak_.step;
  r["peak_time_s"] = peak_.time;
  r["loading_rate"] = {{"platen_velocity_m_per_s", v_final_},
                       {"strain_rate_per_s", 2 * v_final_ / geo_.loaded_length()}};
  if (p_.approach_stress > 0)
    r["loading_rate"]["approach"] = {
        {"stress_Pa", p_.approach_stress},
        {"rate_multiple", p_.approach_rate},
        {"reached_step", approach_end_step_ >= 0 ? nlohmann::json(approach_end_step_) : nullptr}};
  r["timestep_safety"] = m_.settings.timestep_safety;
  if (p_.density_scaling > 0)
    r["density_scaling"] = {
        {"quantile", density_.quantile},
        {"timestep_gain", density_.step_gain},
        {"scaled_grains", density_.scaled},
        {"max_inertia_factor", density_.max_factor},
        {"method", "from the start of loading, the grains whose own stable step was below the "
                   "quantile's got the inertial mass and moment of inertia for that step (gravity "
                   "and outputs keep the true masses)"}};
  test_.results(*this, r);
  energy_results(r);
  quasi_static_results(r);
  nlohmann::json spec = {{"dimension", geo_.dim},
                         {"grains", m_.balls.size()},
                         {"height_m", geo_.height0},
                         {"volume_m3", geo_.volume}};
  spec["center_m"] = geo_.dim == 2
                         ? nlohmann::json({geo_.center.x(), geo_.center.y()})
                         : nlohmann::json({geo_.center.x(), geo_.center.y(), geo_.center.z()});
  if (geo_.diametral) {
    spec["diameter_m"] = geo_.width0.x();
    spec["thickness_m"] = geo_.thickness;
  } else if (geo_.round) {
    spec["diameter_m"] = geo_.width0.x();
  } else {
    spec["width_m"] = geo_.dim == 2 ? nlohmann::json(geo_.width0.x())
                                    : nlohmann::json({geo_.width0.x(), geo_.width0.y()});
  }
  if (meta_.contains("report"))
    spec["porosity"] = meta_["report"].value("porosity", 0.0);
  r["specimen"] = spec;
  return r;
}

} // namespace rocklab
