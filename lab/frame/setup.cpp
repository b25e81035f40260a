// Setting up the loading frame around a specimen: its geometry, the test's fixtures (platens or
// grips, confining walls: lab/frame/fixtures.hpp) and the lateral-surface grains whose motion
// gives the unconfined lateral strain.
#include "lab/frame/loading_frame.hpp"

#include "io/json_input.hpp"
#include "lab/frame/frame_test.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace rocklab {

namespace {
constexpr double kPi = std::numbers::pi;
} // namespace

LoadingFrame::LoadingFrame(const Protocol& p, FrameTest& test, Model& m, const nlohmann::json& meta)
    : p_(p), test_(test), m_(m), meta_(meta), setup_(test.setup()), actuator_(test.actuator(p)),
      confinement_(test.confinement()) {}

void LoadingFrame::setup() {
  m_.settings.slip_events = false; // the lab reads bond_break events only
  m_.clear_events();
  ae_.set_duration(p_.event_window);
  ae_.set_tensors(p_.moment_tensors);
  if (m_.balls.size() == 0)
    throw InputError(p_.file + ": the specimen has no grains");
  const FrameSetup& setup = setup_;
  std::string shape;
  nlohmann::json spec;
  if (meta_.contains("report") && meta_["report"].contains("specimen")) {
    spec = meta_["report"]["specimen"];
    shape = spec.value("shape", "");
  }
  measure_specimen(shape, setup.diametral);
  test_.check_shape(shape, p_);
  test_.read_specimen(spec);
  reference_ = m_.balls.pos;
  m_.balls.track_orientation(p_.orientation); // rotations count from here, like displacements
  const LinearProps props = wall_contact();   // each fixture sets its own friction
  actuator_->mount(m_, geo_, props, p_.file);
  if (confinement_)
    confinement_->mount(m_, geo_, props);
  else if (setup.first_phase == kConfine)
    throw std::logic_error("a test that starts by confining needs confining walls");
  find_shell();
  v_final_ =
      p_.platen_velocity > 0 ? p_.platen_velocity : 0.5 * p_.strain_rate * geo_.loaded_length();
  m_.initialize();
  check_reachable_strain();
  mark_energy_start();
  phase_ = setup.first_phase;
  phase_start_step_ = m_.step();
  if (phase_ == kLoad)
    begin_loading();
  measure(current_);
  record_history();
}

// A loading that cannot strain the specimen measurably within `stop.max_steps` would cycle to the
// limit and report nothing (a rock fails at axial strains of 1e-3 to 1e-2): refused up front.
void LoadingFrame::check_reachable_strain() const {
  const double reach =
      2 * v_final_ * m_.timestep() * static_cast<double>(p_.max_steps) / geo_.loaded_length();
  if (reach >= 1e-4)
    return;
  const bool by_velocity = p_.platen_velocity > 0; // else by strain rate
  std::ostringstream msg;
  msg << p_.file << ": key '" << (by_velocity ? "loading.platen_velocity" : "loading.strain_rate")
      << "': at " << (by_velocity ? p_.platen_velocity : p_.strain_rate)
      << (by_velocity ? " m/s" : " 1/s") << " the " << p_.max_steps
      << " steps of 'stop.max_steps' (time step " << m_.timestep()
      << " s) reach an axial strain of " << reach
      << "; allowed: a rate and step limit that reach at least 1e-4";
  throw InputError(msg.str());
}

void LoadingFrame::measure_specimen(const std::string& shape, bool diametral) {
  SpecimenGeometry& g = geo_;
  const std::size_t n = m_.balls.size();
  g.dim = m_.settings.dim;
  g.diametral = diametral;
  g.axis = diametral ? 1 : (g.dim == 2 ? 1 : 2);
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  double rsum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    lo = lo.cwiseMin(m_.balls.pos[i] - Vec3::Constant(m_.balls.radius[i]));
    hi = hi.cwiseMax(m_.balls.pos[i] + Vec3::Constant(m_.balls.radius[i]));
    rsum += m_.balls.radius[i];
  }
  if (g.dim == 2)
    lo.z() = hi.z() = 0;
  g.lo = lo;
  g.hi = hi;
  g.r_avg = rsum / static_cast<double>(n);
  g.center = 0.5 * (lo + hi);
  g.height0 = hi[g.axis] - lo[g.axis];
  g.round = shape == "cylinder";
  if (diametral) {
    g.width0 = Vec3(hi.x() - lo.x(), hi.y() - lo.y(), 0);
    g.thickness = g.dim == 3 ? hi.z() - lo.z() : 1.0;
    g.area0 = g.width0.x() * g.thickness;
    g.volume = 0.25 * kPi * g.width0.x() * g.width0.y() * g.thickness;
  } else if (g.round) {
    double rmax = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3 d = m_.balls.pos[i] - g.center;
      rmax = std::max(rmax, std::hypot(d.x(), d.y()) + m_.balls.radius[i]);
    }
    g.width0 = Vec3(2 * rmax, 2 * rmax, 0);
    g.area0 = kPi * rmax * rmax;
    g.volume = g.area0 * g.height0;
  } else {
    g.width0 = hi - lo;
    g.width0[g.axis] = 0;
    g.area0 = g.dim == 2 ? g.width0.x() : g.width0.x() * g.width0.y();
    g.volume = g.area0 * g.height0;
  }
}

LinearProps LoadingFrame::wall_contact() const {
  // Contacts with the machine's walls: the specimen's ball-facet linear model; the platens'
  // friction is theirs to set (loading.platen_friction or the test's own), the confining walls'
  // is zero (a lubricated membrane).
  for (const ModelRule& r : m_.rules)
    if (r.ball_facet && r.wall == -1 && std::holds_alternative<LinearProps>(r.props))
      return std::get<LinearProps>(r.props);
  throw InputError(p_.file + ": the specimen has no linear ball-facet contact rule for the "
                             "platens (specimens made by rocklab genesis have one)");
}

void LoadingFrame::find_shell() {
  // Lateral-surface grains: within two mean radii of the side, in the middle 80 % of the height.
  const SpecimenGeometry& g = geo_;
  for (std::size_t i = 0; i < m_.balls.size(); ++i) {
    const Vec3& x = m_.balls.pos[i];
    const double r = m_.balls.radius[i];
    if (std::abs(x[g.axis] - g.center[g.axis]) > 0.4 * g.height0)
      continue;
    bool outer = false;
    if (g.round) {
      const Vec3 d = x - g.center;
      outer = 0.5 * g.width0.x() - (std::hypot(d.x(), d.y()) + r) < 2 * g.r_avg;
    } else {
      for (int d = 0; d < g.dim; ++d)
        if (d != g.axis && (x[d] - r - g.lo[d] < 2 * g.r_avg || g.hi[d] - (x[d] + r) < 2 * g.r_avg))
          outer = true;
    }
    if (outer)
      shell_.push_back(static_cast<std::int32_t>(i));
  }
}

} // namespace rocklab
