#include "lab/lab_test.hpp"

#include "core/servo.hpp"
#include "io/json_input.hpp"
#include "io/output_dir.hpp"
#include "io/results.hpp"
#include "io/specimen.hpp"
#include "materials/genesis.hpp"
#include "viz/svg_plots.hpp"
#include "viz/vtk_output.hpp"

#include <omp.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

namespace rocklab {

namespace fs = std::filesystem;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr std::uint8_t kAllDofs = 0x3f;

// Phases of a test, in order.
enum Phase : int { kConfine = 0, kSeat = 1, kLoad = 2, kUnload = 3, kDone = 4 };

Vec3 unit(int axis) {
  Vec3 e = Vec3::Zero();
  e[axis] = 1;
  return e;
}

// The machine's plane walls keep their own edge direction (n.unitOrthogonal()), so the platens
// are the same facets as before the wall builder moved to core.
Wall machine_wall(int dim, const std::string& name, const Vec3& p, const Vec3& n, double extent) {
  return plane_wall(dim, name, p, n, extent, n.unitOrthogonal());
}

constexpr double kServoIntegralSteps = 100; ///< integral time of the confining servo [steps]
/// Servo gain: the fraction of the stress error closed per step, from the stiffness of the wall's
/// contacts (1: the whole error, the fastest stable proportional control for a stiff contact).
constexpr double kServoGain = 1.0;

double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3 - 2 * x);
}

nlohmann::json vec_json(const std::vector<Vec3>& v) {
  nlohmann::json a = nlohmann::json::array();
  for (const Vec3& x : v)
    a.push_back({x.x(), x.y(), x.z()});
  return a;
}
std::vector<Vec3> vec_from_json(const nlohmann::json& a) {
  std::vector<Vec3> v;
  for (const auto& x : a)
    v.emplace_back(x[0].get<double>(), x[1].get<double>(), x[2].get<double>());
  return v;
}

} // namespace

ElasticFit fit_elastic(const std::vector<LabSample>& s, double peak, double lo, double hi) {
  // Least squares over the pre-peak samples with lo*peak <= load <= hi*peak.
  ElasticFit f;
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, sl = 0, sxl = 0;
  for (const LabSample& p : s) {
    if (p.load >= peak && peak > 0)
      break;
    if (p.load < lo * peak || p.load > hi * peak)
      continue;
    n += 1;
    sx += p.axial_strain;
    sy += p.load;
    sxx += p.axial_strain * p.axial_strain;
    sxy += p.axial_strain * p.load;
    sl += p.lateral_strain;
    sxl += p.axial_strain * p.lateral_strain;
  }
  f.points = static_cast<std::size_t>(n);
  const double den = n * sxx - sx * sx;
  if (n >= 2 && den > 0) {
    f.youngs_modulus = (n * sxy - sx * sy) / den;
    f.poisson_ratio = -(n * sxl - sx * sl) / den;
  }
  return f;
}

SpecimenSource obtain_specimen(const Protocol& p, const std::atomic<bool>* interrupt,
                               bool progress) {
  SpecimenSource src;
  if (!p.specimen_file.empty()) {
    src.model = load_model(p.specimen_file, &src.meta);
    return src;
  }
  MaterialCard card = load_material_card(p.material_file);
  if (!p.shape.is_null())
    card.vessel = shape_from_json(p.shape, card.dim, p.file, "specimen.shape");
  if (!p.cut.is_null())
    card.cut = shape_from_json(p.cut, card.dim, p.file, "specimen.cut");
  if (p.seed)
    card.seed = *p.seed;
  GenesisResult g = run_genesis(
      card,
      [&](const std::string& s) {
        if (progress)
          std::fprintf(stderr, "[rocklab genesis] %s\n", s.c_str());
      },
      interrupt);
  nlohmann::json report = g.report.to_json();
  report.erase("seconds");
  src.meta = {{"rocklab_version", ROCKLAB_VERSION},
              {"material_file", p.material_file},
              {"material_name", card.name},
              {"material_hash", card.text_hash},
              {"seed", card.seed},
              {"material", card.raw},
              {"report", report}};
  src.model = std::move(g.model);
  return src;
}

namespace {

// The machine: platens, confining walls or grips around the specimen; control, measurement and
// records. Everything a continued run depends on is in state() / restore().
class Machine {
public:
  Machine(const Protocol& p, Model& m, const nlohmann::json& meta) : p_(p), m_(m), meta_(meta) {}

  void setup();
  void advance();
  bool done() const { return phase_ == kDone; }
  nlohmann::json state() const;
  void restore(const nlohmann::json& j);
  /// Called after the model was restored: wall indices etc. come from the state.
  nlohmann::json results() const;
  std::string history_csv() const;
  const CrackMonitor& cracks() const { return monitor_; }
  const std::vector<LabSample>& samples() const { return samples_; }
  Snapshot snapshot() const {
    Snapshot s = take_snapshot(m_, reference_, current_.axial_strain);
    for (const Crack& c : monitor_.cracks())
      s.cracks.push_back({c.position, c.normal, c.size, c.mode, c.time, c.step});
    return s;
  }
  bool snapshot_due() const { return snapshot_due_; }
  void snapshot_taken() { snapshot_due_ = false; }
  bool peak_snapshot_due() const { return peak_snap_due_; }
  void peak_snapshot_taken() { peak_snap_due_ = false; }
  const LabSample& current() const { return current_; }
  double peak() const { return peak_; }
  int phase() const { return phase_; }
  std::int64_t loading_steps() const { return phase_ >= kLoad ? m_.step() - load_start_step_ : 0; }
  double volume() const { return volume_; }
  const char* phase_name() const {
    static const char* names[] = {"confining", "seating", "loading", "unloading", "done"};
    return names[phase_];
  }

private:
  void control();
  void measure(LabSample& s) const;
  void record_history();
  void begin_loading();
  void finish(const std::string& why);
  double servo_velocity(std::size_t wall, double target, double area, double stress) const;
  double follow_velocity(std::size_t k) const;
  void gather_wall_sums();
  double separation() const;
  double lateral_width(int d) const;
  double face_area(std::size_t k) const;
  double lateral_stress_of(std::size_t k) const;
  double current_area(double lateral_strain) const;

  const Protocol& p_;
  Model& m_;
  const nlohmann::json& meta_;
  // geometry at the start of the test [m]
  int dim_ = 3;
  int axis_ = 2;       ///< loading axis: z (3D) / y (2D); Brazilian: y
  bool round_ = false; ///< cylinder (3D) cross-section
  Vec3 center_ = Vec3::Zero();
  double height0_ = 0;         ///< along the loading axis
  Vec3 width0_ = Vec3::Zero(); ///< extents across the axis (cylinder: the diameter)
  double thickness_ = 1;       ///< Brazilian disk thickness (2D: unit thickness)
  double area0_ = 0, volume_ = 0, r_avg_ = 0;
  // machine parts
  std::int64_t top_ = -1, bottom_ = -1; ///< platen walls; -1 in direct tension (grips)
  std::vector<std::int64_t> lateral_;   ///< confining walls
  std::vector<int> lateral_axis_;       ///< axis of each (-1: the cylinder)
  std::vector<double> lateral_sign_;    ///< +1 for the wall on the + side
  std::vector<std::int32_t> grip_top_, grip_bottom_, shell_;
  // state
  int phase_ = kSeat;
  std::int64_t phase_start_step_ = 0, load_start_step_ = 0, reverse_step_ = -1;
  double v_final_ = 0; ///< platen (grip) speed while loading [m/s]
  double sep_ref_ = 0; ///< platen or grip separation when loading began [m]
  std::vector<Vec3> shell_ref_;
  Vec3 lateral_ref_ = Vec3::Zero(); ///< wall widths (cylinder radius in [0]) when loading began
  double load_ref_ = 0;             ///< load when loading began (the seating stress)
  std::vector<Vec3> reference_;     ///< grain positions when the test began
  double peak_ = 0, peak_strain_ = 0, peak_stress_ = 0, peak_force_ = 0, peak_lateral_ = 0;
  double peak_time_ = 0;
  std::int64_t peak_step_ = -1, peak_tension_ = 0, peak_shear_ = 0;
  double conf_min_ = 0, conf_max_ = 0, conf_sum_ = 0;
  std::int64_t conf_n_ = 0, conf_win_n_ = 0;
  double conf_win_sum_ = 0, conf_inst_min_ = 0, conf_inst_max_ = 0;
  bool conf_seen_ = false;
  double conf_peak_min_ = 0, conf_peak_max_ = 0; ///< the band up to the peak
  std::vector<double> servo_integral_;           ///< sum of the confinement error of each wall [Pa]
  // per-step servo sums by wall index (derived each step, reused buffers)
  std::vector<double> wall_k_, wall_f_, wall_fv_;
  std::vector<int> lateral_of_wall_;
  std::int64_t bond_break_events_ = 0; ///< bond_break events seen (each becomes a crack)
  double next_snapshot_strain_ = 0;
  bool snapshot_due_ = false, peak_snap_due_ = false;
  std::int64_t peak_snap_step_ = -1;
  std::string stop_reason_;
  // Brazilian split check: which tenths of the loaded diameter hold a crack near it
  std::array<bool, 10> split_bins_{};
  std::size_t split_scanned_ = 0; ///< cracks already binned (rebuilt from the cracks on resume)
  std::int64_t split_step_ = -1;  ///< first stop check (after the drop) that saw the split
  bool split_seen();
  LabSample current_;
  std::vector<LabSample> samples_; ///< fine record of the loading (fits)
  std::vector<std::vector<double>> history_;
  CrackMonitor monitor_;
  std::vector<Event> events_;
};

void Machine::setup() {
  dim_ = m_.settings.dim;
  m_.settings.slip_events = false; // the lab reads bond_break events only
  m_.clear_events();
  const std::size_t n = m_.balls.size();
  if (n == 0)
    throw InputError(p_.file + ": the specimen has no grains");
  axis_ = p_.type == TestType::Brazilian ? 1 : (dim_ == 2 ? 1 : 2);
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  double rsum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    lo = lo.cwiseMin(m_.balls.pos[i] - Vec3::Constant(m_.balls.radius[i]));
    hi = hi.cwiseMax(m_.balls.pos[i] + Vec3::Constant(m_.balls.radius[i]));
    rsum += m_.balls.radius[i];
  }
  if (dim_ == 2)
    lo.z() = hi.z() = 0;
  r_avg_ = rsum / static_cast<double>(n);
  center_ = 0.5 * (lo + hi);
  height0_ = hi[axis_] - lo[axis_];
  std::string shape;
  if (meta_.contains("report") && meta_["report"].contains("specimen"))
    shape = meta_["report"]["specimen"].value("shape", "");
  if (p_.type == TestType::Brazilian && shape != "disk")
    throw InputError(
        p_.file + ": key 'specimen': a Brazilian test needs a disk specimen, not " +
        (shape.empty() ? std::string("a specimen without a genesis record") : "a " + shape) +
        "; give \"shape\": {\"shape\": \"disk\", ...}");
  if (p_.type != TestType::Brazilian && shape == "disk")
    throw InputError(p_.file + ": key 'specimen': a disk specimen is for Brazilian tests; give a "
                               "cylinder, prism or rectangle");
  round_ = shape == "cylinder";
  if (p_.type == TestType::Brazilian) {
    width0_ = Vec3(hi.x() - lo.x(), hi.y() - lo.y(), 0);
    thickness_ = dim_ == 3 ? hi.z() - lo.z() : 1.0;
    area0_ = width0_.x() * thickness_;
    volume_ = 0.25 * kPi * width0_.x() * width0_.y() * thickness_;
  } else if (round_) {
    double rmax = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3 d = m_.balls.pos[i] - center_;
      rmax = std::max(rmax, std::hypot(d.x(), d.y()) + m_.balls.radius[i]);
    }
    width0_ = Vec3(2 * rmax, 2 * rmax, 0);
    area0_ = kPi * rmax * rmax;
    volume_ = area0_ * height0_;
  } else {
    width0_ = hi - lo;
    width0_[axis_] = 0;
    area0_ = dim_ == 2 ? width0_.x() : width0_.x() * width0_.y();
    volume_ = area0_ * height0_;
  }
  reference_ = m_.balls.pos;

  // Contacts with the machine's walls: the specimen's ball-facet linear model, frictionless
  // (lubricated platens) except in the Brazilian test, whose platens keep the specimen's wall
  // friction: between frictionless flat platens a disk is unstable and slides out sideways.
  LinearProps wall_props;
  bool found = false;
  for (const ModelRule& r : m_.rules)
    if (r.ball_facet && r.wall == -1 && std::holds_alternative<LinearProps>(r.props)) {
      wall_props = std::get<LinearProps>(r.props);
      found = true;
      break;
    }
  if (!found)
    throw InputError(p_.file + ": the specimen has no linear ball-facet contact rule for the "
                               "platens (specimens made by rocklab genesis have one)");
  if (p_.type != TestType::Brazilian)
    wall_props.fric = 0;
  auto add_wall = [&](Wall w) {
    m_.walls.push_back(std::move(w));
    ModelRule r;
    r.ball_facet = true;
    r.wall = static_cast<int>(m_.walls.size() - 1);
    r.props = wall_props;
    m_.rules.insert(m_.rules.begin(), r);
    return static_cast<std::int64_t>(m_.walls.size() - 1);
  };
  const Vec3 e = unit(axis_);
  const double span = 3 * std::max({width0_.maxCoeff(), height0_, thickness_});
  if (p_.type == TestType::DirectTension) {
    const double g = p_.grip_fraction * height0_;
    for (std::size_t i = 0; i < n; ++i) {
      const double z = m_.balls.pos[i][axis_];
      if (z - lo[axis_] <= g)
        grip_bottom_.push_back(static_cast<std::int32_t>(i));
      else if (hi[axis_] - z <= g)
        grip_top_.push_back(static_cast<std::int32_t>(i));
    }
    if (grip_top_.empty() || grip_bottom_.empty())
      throw InputError(p_.file + ": key 'loading.grip_fraction': a grip holds no grains");
    if (!m_.clumps.empty())
      throw InputError(p_.file + ": key 'test': the direct-tension grips hold single grains; this "
                                 "specimen has clumps (not supported yet)");
    for (const auto* list : {&grip_top_, &grip_bottom_})
      for (std::int32_t i : *list) {
        const auto k = static_cast<std::size_t>(i);
        m_.balls.fixity[k] = kAllDofs;
        m_.balls.vel[k].setZero();
        m_.balls.spin[k].setZero();
      }
  } else {
    Vec3 ptop = center_, pbot = center_;
    ptop[axis_] = hi[axis_];
    pbot[axis_] = lo[axis_];
    top_ = add_wall(machine_wall(dim_, "platen.top", ptop, -e, span));
    bottom_ = add_wall(machine_wall(dim_, "platen.bottom", pbot, e, span));
  }
  if (p_.type == TestType::Triaxial) {
    if (round_) {
      Wall w;
      w.name = "confinement";
      w.cylinder_radius = 0.5 * width0_.x();
      w.center = center_;
      w.axis = e;
      w.update_bounds();
      lateral_.push_back(add_wall(std::move(w)));
      lateral_axis_.push_back(-1);
      lateral_sign_.push_back(1);
    } else {
      for (int d = 0; d < dim_; ++d) {
        if (d == axis_)
          continue;
        for (int side = 0; side < 2; ++side) {
          Vec3 pt = center_;
          pt[d] = side ? hi[d] : lo[d];
          const Vec3 nrm = side ? Vec3(-unit(d)) : unit(d);
          const std::string name = std::string("confinement.") + "xyz"[d] + (side ? "max" : "min");
          lateral_.push_back(add_wall(machine_wall(dim_, name, pt, nrm, span)));
          lateral_axis_.push_back(d);
          lateral_sign_.push_back(side ? 1.0 : -1.0);
        }
      }
    }
  }
  // Lateral-surface grains (within two mean radii of the side, middle 80 % of the height).
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& x = m_.balls.pos[i];
    const double r = m_.balls.radius[i];
    if (std::abs(x[axis_] - center_[axis_]) > 0.4 * height0_)
      continue;
    bool outer = false;
    if (round_) {
      const Vec3 d = x - center_;
      outer = 0.5 * width0_.x() - (std::hypot(d.x(), d.y()) + r) < 2 * r_avg_;
    } else {
      for (int d = 0; d < dim_; ++d)
        if (d != axis_ && (x[d] - r - lo[d] < 2 * r_avg_ || hi[d] - (x[d] + r) < 2 * r_avg_))
          outer = true;
    }
    if (outer)
      shell_.push_back(static_cast<std::int32_t>(i));
  }
  v_final_ = p_.platen_velocity > 0
                 ? p_.platen_velocity
                 : 0.5 * p_.strain_rate * (p_.type == TestType::Brazilian ? width0_.y() : height0_);
  m_.initialize();
  phase_ = p_.type == TestType::Triaxial        ? kConfine
           : p_.type == TestType::DirectTension ? kLoad
                                                : kSeat;
  phase_start_step_ = m_.step();
  if (phase_ == kLoad)
    begin_loading();
  measure(current_);
  record_history();
}

double Machine::separation() const {
  if (top_ >= 0)
    return m_.walls[static_cast<std::size_t>(top_)].center[axis_] -
           m_.walls[static_cast<std::size_t>(bottom_)].center[axis_];
  double zt = 0, zb = 0;
  for (std::int32_t i : grip_top_)
    zt += m_.balls.pos[static_cast<std::size_t>(i)][axis_];
  for (std::int32_t i : grip_bottom_)
    zb += m_.balls.pos[static_cast<std::size_t>(i)][axis_];
  return zt / static_cast<double>(grip_top_.size()) - zb / static_cast<double>(grip_bottom_.size());
}

double Machine::lateral_width(int d) const {
  double w = 0;
  for (std::size_t j = 0; j < lateral_.size(); ++j)
    if (lateral_axis_[j] == d)
      w += lateral_sign_[j] * m_.walls[static_cast<std::size_t>(lateral_[j])].center[d];
  return w;
}

double Machine::face_area(std::size_t k) const {
  const double h = top_ >= 0 ? separation() : height0_;
  if (lateral_axis_[k] < 0)
    return 2 * kPi * m_.walls[static_cast<std::size_t>(lateral_[k])].cylinder_radius * h;
  if (dim_ == 2)
    return h; // unit thickness
  const int other = 3 - axis_ - lateral_axis_[k];
  return h * lateral_width(other);
}

double Machine::lateral_stress_of(std::size_t k) const {
  const Wall& w = m_.walls[static_cast<std::size_t>(lateral_[k])];
  const double f =
      lateral_axis_[k] < 0 ? w.radial_force : lateral_sign_[k] * w.force[lateral_axis_[k]];
  return f / face_area(k);
}

double Machine::current_area(double lateral_strain) const {
  if (p_.type == TestType::Brazilian || p_.type == TestType::DirectTension)
    return area0_;
  if (!lateral_.empty()) {
    if (lateral_axis_[0] < 0) {
      const double r = m_.walls[static_cast<std::size_t>(lateral_[0])].cylinder_radius;
      return kPi * r * r;
    }
    double a = 1;
    for (int d = 0; d < dim_; ++d)
      if (d != axis_)
        a *= lateral_width(d);
    return a;
  }
  // Unconfined: the initial section widened by the measured lateral strain.
  const double f = 1 - lateral_strain;
  return dim_ == 2 ? area0_ * f : area0_ * f * f;
}

void Machine::gather_wall_sums() {
  // One pass over the contacts per step for every servo-controlled wall: the stiffness sum of its
  // contacts (servo gain) and, for confining walls, the force-weighted inward velocity of the
  // grains touching it (feed-forward). Buffers are reused: nothing is allocated per step.
  const std::size_t nw = m_.walls.size();
  wall_k_.assign(nw, 0.0);
  wall_f_.assign(nw, 0.0);
  wall_fv_.assign(nw, 0.0);
  lateral_of_wall_.assign(nw, -1);
  for (std::size_t k = 0; k < lateral_.size(); ++k)
    lateral_of_wall_[static_cast<std::size_t>(lateral_[k])] = static_cast<int>(k);
  const auto& cs = m_.contacts();
  const auto& os = m_.contact_outputs();
  for (std::size_t ci = 0; ci < cs.size(); ++ci) {
    if (cs[ci].kind != ContactKind::BallFacet)
      continue;
    const auto wall = static_cast<std::size_t>(cs[ci].end2);
    wall_k_[wall] += os[ci].stiff.k_tran;
    const int k = lateral_of_wall_[wall];
    if (k < 0)
      continue;
    const double f = os[ci].force.norm();
    if (f <= 0)
      continue;
    const Wall& w = m_.walls[wall];
    const auto b = static_cast<std::size_t>(cs[ci].end1);
    const Vec3& vel = m_.balls.vel[b];
    const auto kk = static_cast<std::size_t>(k);
    double inward;
    if (lateral_axis_[kk] < 0) {
      Vec3 r = m_.balls.pos[b] - w.center;
      r -= r.dot(w.axis) * w.axis;
      const double rn = r.norm();
      inward = rn > 0 ? -vel.dot(r) / rn : 0.0;
    } else {
      inward = -lateral_sign_[kk] * vel[lateral_axis_[kk]];
    }
    wall_f_[wall] += f;
    wall_fv_[wall] += f * inward;
  }
}

double Machine::servo_velocity(std::size_t wall, double target, double area, double stress) const {
  // Close the stress error in one step, capped at 0.1 % of a mean grain radius per step.
  // Needs gather_wall_sums().
  const double dt = std::max(m_.timestep(), 1e-15);
  return rocklab::servo_velocity(kServoGain, area, wall_k_[wall], dt, target - stress,
                                 1e-3 * r_avg_ / dt);
}

double Machine::follow_velocity(std::size_t k) const {
  // Force-weighted mean velocity, towards the specimen (> 0 inwards), of the grains touching
  // lateral wall k. Needs gather_wall_sums().
  const auto wall = static_cast<std::size_t>(lateral_[k]);
  return wall_f_[wall] > 0 ? wall_fv_[wall] / wall_f_[wall] : 0.0;
}

void Machine::measure(LabSample& s) const {
  s.step = m_.step();
  s.time = m_.time();
  // Platen (grip) force; > 0 compresses the specimen (in direct tension: > 0 pulls it).
  if (top_ >= 0) {
    s.force = 0.5 * (m_.walls[static_cast<std::size_t>(top_)].force[axis_] -
                     m_.walls[static_cast<std::size_t>(bottom_)].force[axis_]);
  } else {
    double ft = 0, fb = 0;
    for (std::int32_t i : grip_top_)
      ft -= m_.balls.force[static_cast<std::size_t>(i)][axis_];
    for (std::int32_t i : grip_bottom_)
      fb += m_.balls.force[static_cast<std::size_t>(i)][axis_];
    s.force = 0.5 * (ft + fb);
  }
  const bool loading = phase_ >= kLoad;
  const double sep = separation();
  s.axial_strain = !loading                             ? 0.0
                   : p_.type == TestType::DirectTension ? (sep - sep_ref_) / height0_
                   : p_.type == TestType::Brazilian     ? (sep_ref_ - sep) / width0_.y()
                                                        : (sep_ref_ - sep) / sep_ref_;
  // Lateral strain, compression positive (bulging is negative).
  s.lateral_strain = 0;
  if (loading && p_.type != TestType::Brazilian) {
    if (!lateral_.empty()) {
      if (lateral_axis_[0] < 0) {
        const double r = m_.walls[static_cast<std::size_t>(lateral_[0])].cylinder_radius;
        s.lateral_strain = -(r - lateral_ref_[0]) / lateral_ref_[0];
      } else {
        double sum = 0;
        int k = 0;
        for (int d = 0; d < dim_; ++d)
          if (d != axis_) {
            sum += -(lateral_width(d) - lateral_ref_[d]) / lateral_ref_[d];
            ++k;
          }
        s.lateral_strain = sum / k;
      }
    } else if (!shell_.empty() && shell_ref_.size() == shell_.size()) {
      if (round_) {
        double ur = 0;
        for (std::size_t k = 0; k < shell_.size(); ++k) {
          const Vec3 x0 = shell_ref_[k] - center_;
          const Vec3 er = Vec3(x0.x(), x0.y(), 0).normalized();
          ur += (m_.balls.pos[static_cast<std::size_t>(shell_[k])] - shell_ref_[k]).dot(er);
        }
        s.lateral_strain = -ur / static_cast<double>(shell_.size()) / (0.5 * width0_.x());
      } else {
        double sum = 0;
        int k = 0;
        for (int d = 0; d < dim_; ++d) {
          if (d == axis_)
            continue;
          double up = 0, un = 0;
          int np = 0, nn = 0;
          for (std::size_t j = 0; j < shell_.size(); ++j) {
            const double x0 = shell_ref_[j][d] - center_[d];
            if (std::abs(x0) < 0.25 * width0_[d])
              continue; // a grain on one of the other faces
            const double u =
                m_.balls.pos[static_cast<std::size_t>(shell_[j])][d] - shell_ref_[j][d];
            (x0 > 0 ? up : un) += u;
            (x0 > 0 ? np : nn) += 1;
          }
          if (np > 0 && nn > 0) {
            sum += -(up / np - un / nn) / width0_[d];
            ++k;
          }
        }
        s.lateral_strain = k ? sum / k : 0.0;
      }
    }
  }
  s.lateral_stress = 0;
  for (std::size_t k = 0; k < lateral_.size(); ++k)
    s.lateral_stress += lateral_stress_of(k) / static_cast<double>(lateral_.size());
  if (p_.type == TestType::Brazilian) {
    // Tensile stress at the disk centre: 2F / (pi D t); 2D: F per unit thickness, t = 1.
    s.axial_stress = 2 * s.force / (kPi * width0_.x() * thickness_);
    s.load = s.axial_stress;
  } else if (p_.type == TestType::DirectTension) {
    s.axial_stress = s.force / area0_;
    s.load = s.axial_stress;
  } else {
    s.axial_stress = s.force / current_area(s.lateral_strain);
    s.load = s.axial_stress - s.lateral_stress; // the deviator (UCS: the axial stress)
  }
}

void Machine::begin_loading() {
  phase_ = kLoad;
  load_start_step_ = phase_start_step_ = m_.step();
  sep_ref_ = separation();
  shell_ref_.clear();
  for (std::int32_t i : shell_)
    shell_ref_.push_back(m_.balls.pos[static_cast<std::size_t>(i)]);
  lateral_ref_.setZero();
  if (!lateral_.empty()) {
    if (lateral_axis_[0] < 0)
      lateral_ref_[0] = m_.walls[static_cast<std::size_t>(lateral_[0])].cylinder_radius;
    else
      for (int d = 0; d < dim_; ++d)
        if (d != axis_)
          lateral_ref_[d] = lateral_width(d);
  }
  LabSample s;
  measure(s);
  load_ref_ = s.load;
  conf_min_ = conf_max_ = conf_inst_min_ = conf_inst_max_ = s.lateral_stress;
  conf_peak_min_ = conf_peak_max_ = s.lateral_stress;
  conf_seen_ = false;
  conf_win_sum_ = 0;
  conf_win_n_ = 0;
  next_snapshot_strain_ = p_.vtk_every_strain;
  snapshot_due_ = p_.vtk; // the start of loading
}

void Machine::control() {
  const Vec3 e = unit(axis_);
  // Confining walls hold the confinement (in every phase). Each wall follows the grains that
  // touch it (feed-forward: the force-weighted mean of their velocity along the wall normal, so a
  // dilating specimen is followed without a standing error), plus a proportional term that
  // closes the whole stress error in one step and a small integral trim (time constant 100 steps,
  // limited to 5 % of the confinement) against any remaining bias.
  if (!lateral_.empty() || phase_ == kConfine || phase_ == kSeat)
    gather_wall_sums();
  if (servo_integral_.size() != lateral_.size())
    servo_integral_.assign(lateral_.size(), 0.0);
  for (std::size_t k = 0; k < lateral_.size(); ++k) {
    const double stress = lateral_stress_of(k);
    const double cap = 0.05 * p_.confinement * kServoIntegralSteps;
    servo_integral_[k] = std::clamp(servo_integral_[k] + p_.confinement - stress, -cap, cap);
    const double v = servo_velocity(static_cast<std::size_t>(lateral_[k]),
                                    p_.confinement + servo_integral_[k] / kServoIntegralSteps,
                                    face_area(k), stress) +
                     follow_velocity(k);
    Wall& w = m_.walls[static_cast<std::size_t>(lateral_[k])];
    if (lateral_axis_[k] < 0)
      w.radial_velocity = -v;
    else
      w.velocity = -lateral_sign_[k] * v * unit(lateral_axis_[k]);
  }
  double v = 0;
  if (phase_ == kConfine || phase_ == kSeat) {
    const double target = phase_ == kConfine ? p_.confinement : p_.seating_stress;
    v = servo_velocity(static_cast<std::size_t>(top_), target, current_area(0),
                       current_.axial_stress);
  } else if (phase_ == kLoad) {
    // Smooth start (PFC ramps the platen velocity too): no stress wave from a sudden jolt.
    const double ramp = p_.ramp_steps > 0 ? static_cast<double>(m_.step() - load_start_step_) /
                                                static_cast<double>(p_.ramp_steps)
                                          : 1.0;
    v = v_final_ * smoothstep(ramp);
  } else if (phase_ == kUnload) {
    const double ramp = p_.ramp_steps > 0 ? static_cast<double>(m_.step() - reverse_step_) /
                                                static_cast<double>(p_.ramp_steps)
                                          : 1.0;
    v = v_final_ * (1 - 2 * smoothstep(ramp));
  }
  if (top_ >= 0) {
    m_.walls[static_cast<std::size_t>(top_)].velocity = -v * e;
    m_.walls[static_cast<std::size_t>(bottom_)].velocity = v * e;
  } else {
    for (std::int32_t i : grip_top_)
      m_.balls.vel[static_cast<std::size_t>(i)] = v * e;
    for (std::int32_t i : grip_bottom_)
      m_.balls.vel[static_cast<std::size_t>(i)] = -v * e;
  }
}

void Machine::record_history() {
  const EnergyLedger en = m_.energy();
  const LabSample& s = current_;
  const double vol =
      s.axial_strain + (dim_ == 2 ? 1.0 : 2.0) * s.lateral_strain; // compression positive
  history_.push_back({s.time, static_cast<double>(s.step), static_cast<double>(phase_),
                      s.axial_strain, s.lateral_strain, vol, s.axial_stress, s.lateral_stress,
                      s.load, s.force, static_cast<double>(monitor_.tension()),
                      static_cast<double>(monitor_.shear()), static_cast<double>(monitor_.total()),
                      en.kinetic(), en.strain, en.bond_strain, en.slip, en.local_damping,
                      en.boundary_work});
}

std::string Machine::history_csv() const {
  std::string s = "time_s,step,phase,axial_strain,lateral_strain,volumetric_strain,axial_stress_Pa,"
                  "lateral_stress_Pa,deviator_Pa,force_N,cracks_tension,cracks_shear,"
                  "cracks_total,kinetic_J,strain_J,bond_strain_J,slip_J,local_damping_J,"
                  "boundary_work_J\n";
  for (const auto& row : history_) {
    for (std::size_t k = 0; k < row.size(); ++k) {
      if (k)
        s += ',';
      s += (k == 1 || k == 2 || (k >= 10 && k <= 12)) ? std::to_string(std::llround(row[k]))
                                                      : format_double(row[k]);
    }
    s += '\n';
  }
  return s;
}

void Machine::finish(const std::string& why) {
  stop_reason_ = why;
  phase_ = kDone;
  for (Wall& w : m_.walls) {
    w.velocity.setZero();
    w.radial_velocity = 0;
  }
  if (history_.empty() || static_cast<std::int64_t>(history_.back()[1]) != m_.step())
    record_history();
}

bool Machine::split_seen() {
  // Cracks within 0.2 D of the loaded diameter (the y axis through the centre), binned by their
  // position along it; a split covers split_fraction of the ten bins without a gap.
  const double d = width0_.y();
  const auto& cracks = monitor_.cracks();
  for (; split_scanned_ < cracks.size(); ++split_scanned_) {
    const Crack& c = cracks[split_scanned_];
    const Vec3 rel = c.position - center_;
    if (std::abs(rel.x()) > 0.2 * d)
      continue;
    const double t = (rel.y() + 0.5 * d) / d;
    const int bin = std::clamp(static_cast<int>(std::floor(t * 10.0)), 0, 9);
    split_bins_[static_cast<std::size_t>(bin)] = true;
  }
  // The longest unbroken run of cracked tenths: crushing under both platens covers the two
  // ends of the diameter but not the middle, a split covers it continuously.
  int run = 0, longest = 0;
  for (bool b : split_bins_) {
    run = b ? run + 1 : 0;
    longest = std::max(longest, run);
  }
  const bool split = longest >= static_cast<int>(std::ceil(p_.split_fraction * 10.0 - 1e-9));
  if (split && split_step_ < 0)
    split_step_ = m_.step();
  return split;
}

void Machine::advance() {
  control();
  m_.cycle(1);
  events_.clear();
  m_.drain_events(events_);
  for (const Event& ev : events_)
    bond_break_events_ += ev.type == EventType::BondBreak ? 1 : 0;
  monitor_.consume(m_, events_);
  measure(current_);
  const std::int64_t since = m_.step() - phase_start_step_;
  const bool check = since % 100 == 0;
  if (phase_ == kConfine || phase_ == kSeat) {
    const double target = phase_ == kConfine ? p_.confinement : p_.seating_stress;
    const double tol = phase_ == kConfine ? p_.confinement_tolerance : 0.1;
    bool ok = std::abs(current_.axial_stress - target) <= tol * target;
    for (std::size_t k = 0; k < lateral_.size(); ++k)
      ok = ok && std::abs(lateral_stress_of(k) - target) <= tol * target;
    if (check && ok && since >= 200 && m_.mean_unbalanced_force_ratio() <= 1e-2) {
      record_history();
      begin_loading();
    } else if (since > p_.max_steps) {
      throw std::runtime_error(p_.file + ": the " + phase_name() +
                               " phase did not reach its stress in " +
                               std::to_string(p_.max_steps) + " steps (key 'stop.max_steps')");
    }
    if (since % p_.history_every == 0)
      record_history();
    return;
  }
  // Loading or unloading.
  const std::int64_t loading = m_.step() - load_start_step_;
  const std::int64_t fine = std::max<std::int64_t>(1, p_.history_every / 10);
  if (loading % fine == 0)
    samples_.push_back(current_);
  if (!lateral_.empty()) {
    // The confinement band is read like a pressure gauge: 100-step means (a few stress-wave
    // transits of a grain), so single-step spikes from breaking bonds do not count; the
    // instantaneous extremes are reported beside it.
    conf_sum_ += current_.lateral_stress;
    ++conf_n_;
    conf_win_sum_ += current_.lateral_stress;
    if (++conf_win_n_ == 100) {
      const double mean = conf_win_sum_ / 100.0;
      conf_min_ = conf_seen_ ? std::min(conf_min_, mean) : mean;
      conf_max_ = conf_seen_ ? std::max(conf_max_, mean) : mean;
      conf_seen_ = true;
      conf_win_sum_ = 0;
      conf_win_n_ = 0;
    }
    conf_inst_min_ = std::min(conf_inst_min_, current_.lateral_stress);
    conf_inst_max_ = std::max(conf_inst_max_, current_.lateral_stress);
  }
  if (phase_ == kLoad && current_.load > peak_) {
    peak_ = current_.load;
    peak_strain_ = current_.axial_strain;
    peak_stress_ = current_.axial_stress;
    peak_force_ = current_.force;
    peak_lateral_ = current_.lateral_strain;
    peak_time_ = current_.time;
    peak_step_ = current_.step;
    peak_tension_ = monitor_.tension();
    peak_shear_ = monitor_.shear();
    conf_peak_min_ = conf_min_;
    conf_peak_max_ = conf_max_;
    if (p_.vtk && m_.step() - peak_snap_step_ >= p_.history_every) {
      peak_snap_due_ = true; // the caller copies a snapshot (throttled)
      peak_snap_step_ = m_.step();
    }
  }
  if (p_.vtk && p_.vtk_every_strain > 0 && phase_ == kLoad &&
      current_.axial_strain >= next_snapshot_strain_) {
    snapshot_due_ = true;
    while (next_snapshot_strain_ <= current_.axial_strain)
      next_snapshot_strain_ += p_.vtk_every_strain;
  }
  if (loading % p_.history_every == 0)
    record_history();
  // Stop rules.
  if (phase_ == kLoad && p_.reverse_at_strain > 0 &&
      current_.axial_strain >= p_.reverse_at_strain) {
    phase_ = kUnload;
    reverse_step_ = m_.step();
    record_history();
    return;
  }
  if (phase_ == kUnload) {
    if (current_.axial_strain <= 0 || current_.load <= load_ref_)
      finish("unloaded to the start");
    else if (loading > p_.max_steps)
      finish("stop.max_steps reached");
    return;
  }
  const bool dropped =
      loading >= p_.min_steps && peak_ > load_ref_ && current_.load < p_.post_peak_fraction * peak_;
  if (dropped && p_.type == TestType::Brazilian && p_.split_fraction > 0) {
    // A disk can lose load locally (a grain crushed under a platen) and reload; only a split
    // along the loaded diameter ends the test, or a load collapse below failed_fraction.
    if (split_seen())
      finish("the disk split and the load fell below " + format_double(p_.post_peak_fraction) +
             " of its peak");
    else if (current_.load < p_.failed_fraction * peak_)
      finish("the load fell below " + format_double(p_.failed_fraction) +
             " of its peak without a split along the loaded diameter");
    else if (loading > p_.max_steps)
      finish("stop.max_steps reached");
  } else if (dropped)
    finish("the load fell below " + format_double(p_.post_peak_fraction) + " of its peak");
  else if (p_.strain_limit > 0 && current_.axial_strain >= p_.strain_limit)
    finish("stop.strain_limit reached");
  else if (loading > p_.max_steps)
    finish("stop.max_steps reached");
}

nlohmann::json Machine::state() const {
  nlohmann::json s;
  s["phase"] = phase_;
  s["phase_start_step"] = phase_start_step_;
  s["load_start_step"] = load_start_step_;
  s["reverse_step"] = reverse_step_;
  s["dim"] = dim_;
  s["axis"] = axis_;
  s["round"] = round_;
  s["center"] = {center_.x(), center_.y(), center_.z()};
  s["height0"] = height0_;
  s["width0"] = {width0_.x(), width0_.y(), width0_.z()};
  s["thickness"] = thickness_;
  s["area0"] = area0_;
  s["volume"] = volume_;
  s["r_avg"] = r_avg_;
  s["top"] = top_;
  s["bottom"] = bottom_;
  s["lateral"] = lateral_;
  s["lateral_axis"] = lateral_axis_;
  s["lateral_sign"] = lateral_sign_;
  s["grip_top"] = grip_top_;
  s["grip_bottom"] = grip_bottom_;
  s["shell"] = shell_;
  s["v_final"] = v_final_;
  s["sep_ref"] = sep_ref_;
  s["shell_ref"] = vec_json(shell_ref_);
  s["lateral_ref"] = {lateral_ref_.x(), lateral_ref_.y(), lateral_ref_.z()};
  s["load_ref"] = load_ref_;
  s["reference"] = vec_json(reference_);
  s["peak"] = {peak_,      peak_strain_, peak_stress_,  peak_force_, peak_lateral_,
               peak_time_, peak_step_,   peak_tension_, peak_shear_};
  s["confinement_stats"] = {conf_min_,     conf_max_,      conf_sum_,      conf_n_,
                            conf_win_sum_, conf_win_n_,    conf_inst_min_, conf_inst_max_,
                            conf_seen_,    conf_peak_min_, conf_peak_max_};
  s["bond_break_events"] = bond_break_events_;
  s["servo_integral"] = servo_integral_;
  s["next_snapshot_strain"] = next_snapshot_strain_;
  s["snapshot_due"] = snapshot_due_;
  s["peak_snap_step"] = peak_snap_step_;
  s["stop_reason"] = stop_reason_;
  s["split_step"] = split_step_;
  nlohmann::json samples = nlohmann::json::array();
  for (const LabSample& x : samples_)
    samples.push_back({x.step, x.time, x.axial_strain, x.lateral_strain, x.axial_stress,
                       x.lateral_stress, x.load, x.force});
  s["samples"] = samples;
  s["history"] = history_;
  s["cracks"] = monitor_.to_json();
  return s;
}

void Machine::restore(const nlohmann::json& s) {
  auto v3 = [](const nlohmann::json& a) {
    return Vec3(a[0].get<double>(), a[1].get<double>(), a[2].get<double>());
  };
  phase_ = s["phase"];
  phase_start_step_ = s["phase_start_step"];
  load_start_step_ = s["load_start_step"];
  reverse_step_ = s["reverse_step"];
  dim_ = s["dim"];
  axis_ = s["axis"];
  round_ = s["round"];
  center_ = v3(s["center"]);
  height0_ = s["height0"];
  width0_ = v3(s["width0"]);
  thickness_ = s["thickness"];
  area0_ = s["area0"];
  volume_ = s["volume"];
  r_avg_ = s["r_avg"];
  top_ = s["top"];
  bottom_ = s["bottom"];
  lateral_ = s["lateral"].get<std::vector<std::int64_t>>();
  lateral_axis_ = s["lateral_axis"].get<std::vector<int>>();
  lateral_sign_ = s["lateral_sign"].get<std::vector<double>>();
  grip_top_ = s["grip_top"].get<std::vector<std::int32_t>>();
  grip_bottom_ = s["grip_bottom"].get<std::vector<std::int32_t>>();
  shell_ = s["shell"].get<std::vector<std::int32_t>>();
  v_final_ = s["v_final"];
  sep_ref_ = s["sep_ref"];
  shell_ref_ = vec_from_json(s["shell_ref"]);
  lateral_ref_ = v3(s["lateral_ref"]);
  load_ref_ = s["load_ref"];
  reference_ = vec_from_json(s["reference"]);
  const auto& pk = s["peak"];
  peak_ = pk[0];
  peak_strain_ = pk[1];
  peak_stress_ = pk[2];
  peak_force_ = pk[3];
  peak_lateral_ = pk[4];
  peak_time_ = pk[5];
  peak_step_ = pk[6];
  peak_tension_ = pk[7];
  peak_shear_ = pk[8];
  const auto& cs = s["confinement_stats"];
  conf_min_ = cs[0];
  conf_max_ = cs[1];
  conf_sum_ = cs[2];
  conf_n_ = cs[3];
  conf_win_sum_ = cs[4];
  conf_win_n_ = cs[5];
  conf_inst_min_ = cs[6];
  conf_inst_max_ = cs[7];
  conf_seen_ = cs[8];
  conf_peak_min_ = cs[9];
  conf_peak_max_ = cs[10];
  bond_break_events_ = s["bond_break_events"];
  servo_integral_ = s["servo_integral"].get<std::vector<double>>();
  next_snapshot_strain_ = s["next_snapshot_strain"];
  snapshot_due_ = s["snapshot_due"];
  peak_snap_step_ = s["peak_snap_step"];
  stop_reason_ = s["stop_reason"];
  split_step_ = s.value("split_step", std::int64_t{-1});
  split_bins_.fill(false);
  split_scanned_ = 0; // rebinned from the restored cracks at the next check
  samples_.clear();
  for (const auto& x : s["samples"])
    samples_.push_back({x[0].get<std::int64_t>(), x[1].get<double>(), x[2].get<double>(),
                        x[3].get<double>(), x[4].get<double>(), x[5].get<double>(),
                        x[6].get<double>(), x[7].get<double>()});
  history_ = s["history"].get<std::vector<std::vector<double>>>();
  monitor_.from_json(s["cracks"]);
  m_.settings.slip_events = false;
  measure(current_);
}

nlohmann::json Machine::results() const {
  nlohmann::json r;
  r["units"] = "SI (m, kg, s, N, Pa, J); stresses and strains compression positive";
  r["test"] = test_type_name(p_.type);
  r["stop_reason"] = stop_reason_;
  if (p_.type == TestType::Brazilian && p_.split_fraction > 0)
    r["split"] = {{"found", split_step_ >= 0},
                  {"step", split_step_},
                  {"fraction_required", p_.split_fraction}};
  const double crack_area = [&] {
    double a = 0;
    for (const Crack& c : monitor_.cracks())
      a += dim_ == 2 ? c.size : 0.25 * kPi * c.size * c.size;
    return a;
  }();
  r["cracks"] = {{"tension", monitor_.tension()},
                 {"shear", monitor_.shear()},
                 {"total", monitor_.total()},
                 {"at_peak",
                  {{"tension", peak_tension_},
                   {"shear", peak_shear_},
                   {"total", peak_tension_ + peak_shear_}}},
                 {"density_per_m3", static_cast<double>(monitor_.total()) / volume_},
                 {"area_per_volume_per_m", crack_area / volume_}};
  r["bond_break_events"] = bond_break_events_;
  r["peak_step"] = peak_step_;
  r["peak_time_s"] = peak_time_;
  r["loading_rate"] = {{"platen_velocity_m_per_s", v_final_},
                       {"strain_rate_per_s",
                        2 * v_final_ / (p_.type == TestType::Brazilian ? width0_.y() : height0_)}};
  if (p_.type == TestType::Ucs || p_.type == TestType::Triaxial) {
    const ElasticFit tangent = fit_elastic(samples_, peak_, 0.4, 0.6);
    double secant = 0;
    for (const LabSample& s : samples_)
      if (s.load >= 0.5 * peak_ && s.axial_strain > 0) {
        secant = (s.load - load_ref_) / s.axial_strain;
        break;
      }
    ElasticFit initial;
    {
      std::vector<LabSample> early;
      for (const LabSample& s : samples_)
        if (s.load - load_ref_ <= 0.01 * peak_ && s.step <= peak_step_)
          early.push_back(s);
      initial = fit_elastic(early, 1e300, -1e300, 1e300);
    }
    r["youngs_modulus_Pa"] = tangent.youngs_modulus;
    r["youngs_modulus_secant_Pa"] = secant;
    r["youngs_modulus_initial_Pa"] = initial.youngs_modulus;
    r["poisson_ratio"] = tangent.poisson_ratio;
    r["peak_stress_Pa"] = peak_stress_;
    r["peak_deviator_Pa"] = peak_;
    r["peak_axial_strain"] = peak_strain_;
    r["peak_lateral_strain"] = peak_lateral_;
    r["confinement_Pa"] = p_.confinement;
    if (!lateral_.empty())
      r["confinement_measured_Pa"] = {
          {"mean", conf_n_ ? conf_sum_ / static_cast<double>(conf_n_) : 0.0},
          {"min", conf_min_},
          {"max", conf_max_},
          {"averaging_steps", 100},
          {"before_peak_min", conf_peak_min_},
          {"before_peak_max", conf_peak_max_},
          {"instantaneous_min", conf_inst_min_},
          {"instantaneous_max", conf_inst_max_}};
    if (p_.reverse_at_strain > 0) {
      // Loading and unloading slopes over the same strain range (20-100 % of the reversal),
      // each once the platens run at full speed (after the ramps at the start and the turn).
      std::vector<LabSample> up, down;
      for (const LabSample& s : samples_) {
        if (s.axial_strain < 0.2 * p_.reverse_at_strain)
          continue;
        if (s.step <= reverse_step_) {
          if (s.step >= load_start_step_ + p_.ramp_steps)
            up.push_back(s);
        } else if (s.step >= reverse_step_ + p_.ramp_steps) {
          down.push_back(s);
        }
      }
      r["youngs_modulus_loading_Pa"] = fit_elastic(up, 1e300, -1e300, 1e300).youngs_modulus;
      r["youngs_modulus_unloading_Pa"] = fit_elastic(down, 1e300, -1e300, 1e300).youngs_modulus;
    }
  } else {
    r["tensile_strength_Pa"] = peak_;
    r["peak_force_N"] = peak_force_;
    r["peak_axial_strain"] = peak_strain_;
    if (p_.type == TestType::DirectTension)
      r["youngs_modulus_Pa"] = fit_elastic(samples_, peak_, 0.4, 0.6).youngs_modulus;
  }
  nlohmann::json spec = {{"dimension", dim_},
                         {"grains", m_.balls.size()},
                         {"height_m", height0_},
                         {"volume_m3", volume_}};
  if (p_.type == TestType::Brazilian) {
    spec["diameter_m"] = width0_.x();
    spec["thickness_m"] = thickness_;
  } else if (round_) {
    spec["diameter_m"] = width0_.x();
  } else {
    spec["width_m"] =
        dim_ == 2 ? nlohmann::json(width0_.x()) : nlohmann::json({width0_.x(), width0_.y()});
  }
  if (meta_.contains("report"))
    spec["porosity"] = meta_["report"].value("porosity", 0.0);
  r["specimen"] = spec;
  return r;
}

} // namespace

LabSummary run_lab_test(const Protocol& p, const LabOptions& o) {
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  LabSummary sum;
  OutputDir out(o.out_dir);
  const std::string checkpoint =
      o.checkpoint_path.empty() ? o.out_dir + ".checkpoint" : o.checkpoint_path;
  std::unique_ptr<Model> model;
  nlohmann::json meta;
  nlohmann::json state;
  std::vector<double> vtk_times;
  std::map<std::string, double> vtk_tagged;
  const fs::path vtk_dir = out.staged("vtk");
  if (!o.resume_path.empty()) {
    nlohmann::json cmeta;
    model = load_model(o.resume_path, &cmeta);
    if (!cmeta.contains("lab") || !cmeta["lab"].contains("machine"))
      throw InputError(o.resume_path + ": not a rocklab test checkpoint");
    if (cmeta["lab"].value("protocol_hash", "") != p.text_hash)
      throw InputError(o.resume_path +
                       ": the checkpoint belongs to another protocol (key "
                       "'protocol_hash' differs from " +
                       p.file + ")");
    meta = cmeta["lab"]["specimen_meta"];
    state = cmeta["lab"]["machine"];
    vtk_times = cmeta["lab"]["vtk_times"].get<std::vector<double>>();
    vtk_tagged = cmeta["lab"]["vtk_tagged"].get<std::map<std::string, double>>();
    sum.files = cmeta["lab"]["files"].get<std::vector<std::string>>();
    // Files written before the checkpoint (specimen, snapshots) were saved beside it.
    const fs::path saved = o.resume_path + ".files";
    if (fs::exists(saved))
      fs::copy(saved, out.staged(""),
               fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  } else {
    SpecimenSource src = obtain_specimen(p, o.interrupt, o.progress);
    model = std::move(src.model);
    meta = std::move(src.meta);
    if (!p.material_file.empty()) {
      save_model(*model, out.staged("specimen.rlspec").string(), meta);
      sum.files.push_back("specimen.rlspec");
    }
  }
  Model& m = *model;
  Machine machine(p, m, meta);
  VtkSeries vtk(vtk_dir);
  if (state.is_null()) {
    machine.setup();
  } else {
    machine.restore(state);
    vtk.set_times(vtk_times);
    vtk.set_tagged(vtk_tagged);
  }
  Snapshot peak_snap;
  bool have_peak_snap = false;
  auto write_checkpoint = [&] {
    // A peak snapshot still in memory goes into the series now, so a resumed run has it too.
    if (have_peak_snap) {
      vtk.write(peak_snap, "peak");
      have_peak_snap = false;
    }
    nlohmann::json cmeta = {{"lab",
                             {{"protocol_file", p.file},
                              {"protocol_hash", p.text_hash},
                              {"specimen_meta", meta},
                              {"machine", machine.state()},
                              {"vtk_times", vtk.times()},
                              {"vtk_tagged", vtk.tagged()},
                              {"files", sum.files}}}};
    // The files written so far are kept beside the checkpoint (a copy of the staging folder).
    const fs::path files = checkpoint + ".files";
    const fs::path tmp = checkpoint + ".files.partial";
    std::error_code ec;
    fs::remove_all(tmp, ec);
    fs::create_directories(tmp);
    fs::copy(out.staged(""), tmp, fs::copy_options::recursive);
    save_model(m, checkpoint + ".pending", cmeta);
    fs::remove_all(files, ec);
    fs::rename(tmp, files);
    fs::rename(checkpoint + ".pending", checkpoint);
  };
  auto last_print = clock::now();
  while (!machine.done()) {
    machine.advance();
    if (machine.snapshot_due()) {
      if (p.vtk)
        vtk.write(machine.snapshot());
      machine.snapshot_taken();
    }
    if (machine.peak_snapshot_due()) {
      peak_snap = machine.snapshot();
      have_peak_snap = true;
      machine.peak_snapshot_taken();
    }
    if (o.checkpoint_every > 0 && m.step() % o.checkpoint_every == 0)
      write_checkpoint();
    if (o.interrupt && o.interrupt->load()) {
      if (o.checkpoint_every > 0)
        write_checkpoint();
      sum.interrupted = true;
      return sum; // OUTDIR is left untouched (the staging folder goes away)
    }
    if (o.progress && clock::now() - last_print > std::chrono::seconds(2)) {
      last_print = clock::now();
      const LabSample& c = machine.current();
      std::fprintf(stderr,
                   "[rocklab test] %s: step %lld  axial strain %.4g  stress %.4g Pa  peak %.4g Pa"
                   "  cracks %lld\n",
                   machine.phase_name(), static_cast<long long>(m.step()), c.axial_strain,
                   c.axial_stress, machine.peak(),
                   static_cast<long long>(machine.cracks().total()));
    }
  }
  // The final snapshot, and the latest peak snapshot (as the "peak" files, placed in the .pvd by
  // its time; a checkpoint may have written an earlier one already).
  if (p.vtk) {
    if (have_peak_snap)
      vtk.write(peak_snap, "peak");
    vtk.write(machine.snapshot());
    for (const std::string& f : vtk.write_collections())
      sum.files.push_back("vtk/" + f);
  }
  sum.wall_seconds = std::chrono::duration<double>(clock::now() - t0).count();
  nlohmann::json r = machine.results();
  r["protocol"] = p.file;
  r["provenance"] = {{"rocklab_version", ROCKLAB_VERSION},
                     {"material", meta.value("material_name", "")},
                     {"material_file", meta.value("material_file", "")},
                     {"material_hash", meta.value("material_hash", "")},
                     {"seed", meta.value("seed", std::uint64_t{0})},
                     {"specimen_file", p.specimen_file},
                     {"protocol_hash", p.text_hash},
                     {"grains", m.balls.size()},
                     {"steps", m.step()},
                     {"model_time_s", m.time()},
                     {"threads", omp_get_max_threads()},
                     {"wall_time_s", sum.wall_seconds}};
  write_text_file(out.staged("history.csv"), machine.history_csv());
  write_text_file(out.staged("cracks.csv"), machine.cracks().csv());
  sum.files.insert(sum.files.end(), {"results.json", "history.csv", "cracks.csv"});
  if (p.plots) {
    // Stress-strain plot with crack counts; crack map of the final state.
    PlotSeries axial{"axial stress vs axial strain", {}, {}, "#000000"};
    PlotSeries lateral{"axial stress vs lateral strain", {}, {}, "#7f7f7f", true};
    PlotSeries ct{"tensile cracks", {}, {}, "#d62728", false, true};
    PlotSeries cs{"shear cracks", {}, {}, "#1f3fbf", false, true};
    std::size_t crack_i = 0;
    std::int64_t nt = 0, ns = 0;
    const auto& cracks = machine.cracks().cracks();
    for (const LabSample& s : machine.samples()) {
      while (crack_i < cracks.size() && cracks[crack_i].step <= s.step)
        (cracks[crack_i++].mode == 1 ? nt : ns) += 1;
      axial.x.push_back(100 * s.axial_strain);
      axial.y.push_back(1e-6 * s.axial_stress);
      ct.x.push_back(100 * s.axial_strain);
      ct.y.push_back(static_cast<double>(nt));
      cs.x.push_back(100 * s.axial_strain);
      cs.y.push_back(static_cast<double>(ns));
      if (p.type == TestType::Ucs || p.type == TestType::Triaxial) {
        lateral.x.push_back(100 * s.lateral_strain);
        lateral.y.push_back(1e-6 * s.axial_stress);
      }
    }
    std::vector<PlotSeries> series{axial};
    if (!lateral.x.empty())
      series.push_back(lateral);
    series.push_back(ct);
    series.push_back(cs);
    const std::string ylabel = p.type == TestType::Brazilian       ? "2F / (pi D t) [MPa]"
                               : p.type == TestType::DirectTension ? "tensile stress [MPa]"
                                                                   : "axial stress [MPa]";
    const std::string xlabel = p.type == TestType::Brazilian ? "platen displacement / D [%]"
                                                             : "strain [%] (compression positive)";
    const std::string title = std::string(test_type_name(p.type)) +
                              " test: " + meta.value("material_name", std::string("specimen"));
    write_text_file(out.staged("stress_strain.svg"),
                    line_plot_svg(title, xlabel, ylabel, "cracks", series));
    write_text_file(out.staged("crack_map.svg"),
                    crack_map_svg(machine.snapshot(), title + ", cracks at the end",
                                  p.type == TestType::Brazilian ? 2 : 1));
    sum.files.insert(sum.files.end(), {"stress_strain.svg", "crack_map.svg"});
  }
  nlohmann::json files = sum.files;
  r["files"] = files;
  sum.results = r;
  write_text_file(out.staged("results.json"), r.dump(2) + "\n");
  out.commit();
  // A finished run needs no checkpoint.
  std::error_code ec;
  if (o.checkpoint_every > 0 || !o.resume_path.empty()) {
    fs::remove(checkpoint, ec);
    fs::remove_all(checkpoint + ".files", ec);
  }
  return sum;
}

} // namespace rocklab
