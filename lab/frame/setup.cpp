// Setting up the loading frame around a specimen: its geometry, the platens (or grips), the
// confining walls and the lateral-surface grains whose motion gives the unconfined lateral strain.
#include "lab/frame/loading_frame.hpp"

#include "io/json_input.hpp"
#include "lab/protocols/frame_protocol.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

namespace rocklab {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr std::uint8_t kAllDofs = 0x3f;

Vec3 unit(int axis) {
  Vec3 e = Vec3::Zero();
  e[axis] = 1;
  return e;
}

// The machine's plane walls keep their own edge direction (n.unitOrthogonal()): the platens are
// the same facets as before the wall builder moved to core/walls.
Wall machine_wall(int dim, const std::string& name, const Vec3& p, const Vec3& n, double extent) {
  return plane_wall(dim, name, p, n, extent, n.unitOrthogonal());
}

} // namespace

void LoadingFrame::setup() {
  m_.settings.slip_events = false; // the lab reads bond_break events only
  m_.clear_events();
  if (m_.balls.size() == 0)
    throw InputError(p_.file + ": the specimen has no grains");
  const FrameSetup setup = test_.setup();
  std::string shape;
  if (meta_.contains("report") && meta_["report"].contains("specimen"))
    shape = meta_["report"]["specimen"].value("shape", "");
  measure_specimen(shape, setup.diametral);
  test_.check_shape(shape, p_);
  reference_ = m_.balls.pos;
  m_.balls.track_orientation(p_.orientation); // rotations count from here, like displacements
  const LinearProps props = platen_contact(setup.platen_friction);
  if (setup.actuator == Actuator::Grips)
    add_grips();
  else
    add_platens(platen_props(props));
  if (setup.confined)
    add_confinement(props);
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

LinearProps LoadingFrame::platen_contact(bool friction) const {
  // Contacts with the machine's walls: the specimen's ball-facet linear model, frictionless
  // (lubricated platens) unless the test keeps the specimen's wall friction (Brazilian: between
  // frictionless flat platens a disk is unstable and slides out sideways).
  for (const ModelRule& r : m_.rules)
    if (r.ball_facet && r.wall == -1 && std::holds_alternative<LinearProps>(r.props)) {
      LinearProps props = std::get<LinearProps>(r.props);
      if (!friction)
        props.fric = 0;
      return props;
    }
  throw InputError(p_.file + ": the specimen has no linear ball-facet contact rule for the "
                             "platens (specimens made by rocklab genesis have one)");
}

LinearProps LoadingFrame::platen_props(LinearProps props) const {
  // loading.platen_friction: end friction of unlubricated platens (the confining walls, a
  // membrane, stay as the test has them).
  if (p_.platen_friction >= 0)
    props.fric = p_.platen_friction;
  return props;
}

std::int64_t LoadingFrame::add_wall(Wall w, const LinearProps& props) {
  m_.walls.push_back(std::move(w));
  ModelRule r;
  r.ball_facet = true;
  r.wall = static_cast<int>(m_.walls.size() - 1);
  r.props = props;
  m_.rules.insert(m_.rules.begin(), r);
  return static_cast<std::int64_t>(m_.walls.size() - 1);
}

void LoadingFrame::add_platens(const LinearProps& props) {
  const SpecimenGeometry& g = geo_;
  const Vec3 e = unit(g.axis);
  const double span = 3 * std::max({g.width0.maxCoeff(), g.height0, g.thickness});
  Vec3 ptop = g.center, pbot = g.center;
  ptop[g.axis] = g.hi[g.axis];
  pbot[g.axis] = g.lo[g.axis];
  if (g.diametral && p_.jaw_radius_ratio > 0) {
    top_ = add_wall(curved_jaw("platen.top", 1), props);
    bottom_ = add_wall(curved_jaw("platen.bottom", -1), props);
    return;
  }
  top_ = add_wall(machine_wall(g.dim, "platen.top", ptop, -e, span), props);
  bottom_ = add_wall(machine_wall(g.dim, "platen.bottom", pbot, e, span), props);
}

// An ISRM curved jaw (ISRM 1978: radius 1.5 times the disk's) as the machine's exact circle (2D)
// or cylinder along the disk's axis z (3D): the disk lies inside it, touching it only near the
// loaded end of its diameter (0.38 R of clearance at the disk's equator for a ratio of 1.5). Its
// centre is on the loaded diameter, placed so that the circle just clears every grain.
Wall LoadingFrame::curved_jaw(const std::string& name, int side) const {
  const SpecimenGeometry& g = geo_;
  const double rj = jaw_radius();
  double yc = side > 0 ? -1e300 : 1e300; // top: the lowest centre that clears; bottom: highest
  for (std::size_t i = 0; i < m_.balls.size(); ++i) {
    const double dx = m_.balls.pos[i].x() - g.center.x(), reach = rj - m_.balls.radius[i];
    const double h = std::sqrt(std::max(reach * reach - dx * dx, 0.0));
    const double y = m_.balls.pos[i].y();
    yc = side > 0 ? std::max(yc, y - h) : std::min(yc, y + h);
  }
  Wall w;
  w.name = name;
  w.cylinder_radius = rj;
  w.center = Vec3(g.center.x(), yc, g.center.z());
  w.axis = Vec3::UnitZ();
  w.update_bounds();
  return w;
}

void LoadingFrame::add_grips() {
  // Grips hold the grains within grip_fraction of the height from each end.
  const SpecimenGeometry& g = geo_;
  const double reach = p_.grip_fraction * g.height0;
  for (std::size_t i = 0; i < m_.balls.size(); ++i) {
    const double z = m_.balls.pos[i][g.axis];
    if (z - g.lo[g.axis] <= reach)
      grip_bottom_.push_back(static_cast<std::int32_t>(i));
    else if (g.hi[g.axis] - z <= reach)
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
}

void LoadingFrame::add_confinement(const LinearProps& props) {
  // A cylinder around a round specimen, plates on the faces of a prism (2D: on the sides).
  const SpecimenGeometry& g = geo_;
  const Vec3 e = unit(g.axis);
  if (g.round) {
    Wall w;
    w.name = "confinement";
    w.cylinder_radius = 0.5 * g.width0.x();
    w.center = g.center;
    w.axis = e;
    w.update_bounds();
    lateral_.push_back(add_wall(std::move(w), props));
    lateral_axis_.push_back(-1);
    lateral_sign_.push_back(1);
    return;
  }
  const double span = 3 * std::max({g.width0.maxCoeff(), g.height0, g.thickness});
  for (int d = 0; d < g.dim; ++d) {
    if (d == g.axis)
      continue;
    for (int side = 0; side < 2; ++side) {
      Vec3 pt = g.center;
      pt[d] = side ? g.hi[d] : g.lo[d];
      const Vec3 nrm = side ? Vec3(-unit(d)) : unit(d);
      const std::string name = std::string("confinement.") + "xyz"[d] + (side ? "max" : "min");
      lateral_.push_back(add_wall(machine_wall(g.dim, name, pt, nrm, span), props));
      lateral_axis_.push_back(d);
      lateral_sign_.push_back(side ? 1.0 : -1.0);
    }
  }
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
