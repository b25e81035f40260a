// The fixtures that carry the load along the axis: flat platens, ISRM curved jaws and grips
// (lab/frame/fixtures.hpp).
#include "lab/frame/fixtures.hpp"

#include "core/servo.hpp"
#include "io/json_fields.hpp"

#include <algorithm>
#include <cmath>

namespace rocklab {

namespace {

constexpr std::uint8_t kAllDofs = 0x3f;
/// Servo gain: the fraction of the stress error closed per step, from the stiffness of the wall's
/// contacts (1: the whole error, the fastest stable proportional control for a stiff contact).
constexpr double kServoGain = 1.0;

[[noreturn]] void corrupt(const std::string& file, const char* what) {
  throw InputError(file + ": corrupt checkpoint (" + what + " out of range)");
}

} // namespace

std::int64_t add_machine_wall(Model& m, Wall w, const LinearProps& props) {
  m.walls.push_back(std::move(w));
  ModelRule r;
  r.ball_facet = true;
  r.wall = static_cast<int>(m.walls.size() - 1);
  r.props = props;
  m.rules.insert(m.rules.begin(), r);
  return static_cast<std::int64_t>(m.walls.size() - 1);
}

// The machine's plane walls keep their own edge direction (n.unitOrthogonal()): the platens are
// the same facets as before the wall builder moved to core/walls.
Wall machine_wall(int dim, const std::string& name, const Vec3& p, const Vec3& n, double extent) {
  return plane_wall(dim, name, p, n, extent, n.unitOrthogonal());
}

double machine_servo_velocity(const Model& m, const SpecimenGeometry& g, double k_sum,
                              double target, double area, double stress) {
  const double dt = std::max(m.timestep(), 1e-15);
  return servo_velocity(kServoGain, area, k_sum, dt, target - stress, 1e-3 * g.r_avg / dt);
}

double curved_jaw_radius(double ratio, const SpecimenGeometry& g) {
  return ratio * 0.5 * g.width0.x();
}

void Platens::mount(Model& m, const SpecimenGeometry& g, const LinearProps& contact,
                    const std::string&) {
  // loading.platen_friction: end friction of unlubricated platens (the confining walls, a
  // membrane, stay as the test has them).
  LinearProps props = contact;
  if (friction_)
    props.fric = *friction_;
  // A cushion (loading.platen_stiffness_ratio): every platen contact softer by the same factor,
  // whether its stiffness is given (kn, ks) or follows from the modulus (deformability).
  props.kn *= stiffness_;
  props.ks *= stiffness_;
  props.emod *= stiffness_;
  if (g.diametral && jaw_ratio_ > 0) {
    top_ = add_machine_wall(m, curved_jaw(m, g, "platen.top", 1), props);
    bottom_ = add_machine_wall(m, curved_jaw(m, g, "platen.bottom", -1), props);
    return;
  }
  const Vec3 e = unit_axis(g.axis);
  const double span = g.machine_span();
  Vec3 ptop = g.center, pbot = g.center;
  ptop[g.axis] = g.hi[g.axis];
  pbot[g.axis] = g.lo[g.axis];
  top_ = add_machine_wall(m, machine_wall(g.dim, "platen.top", ptop, -e, span), props);
  bottom_ = add_machine_wall(m, machine_wall(g.dim, "platen.bottom", pbot, e, span), props);
}

// An ISRM curved jaw (ISRM 1978: radius 1.5 times the disk's) as the machine's exact circle (2D)
// or cylinder along the disk's axis z (3D): the disk lies inside it, touching it only near the
// loaded end of its diameter (0.38 R of clearance at the disk's equator for a ratio of 1.5). Its
// centre is on the loaded diameter, placed so that the circle just clears every grain.
Wall Platens::curved_jaw(const Model& m, const SpecimenGeometry& g, const std::string& name,
                         int side) const {
  const double rj = curved_jaw_radius(jaw_ratio_, g);
  double yc = side > 0 ? -1e300 : 1e300; // top: the lowest centre that clears; bottom: highest
  for (std::size_t i = 0; i < m.balls.size(); ++i) {
    const double dx = m.balls.pos[i].x() - g.center.x(), reach = rj - m.balls.radius[i];
    const double h = std::sqrt(std::max(reach * reach - dx * dx, 0.0));
    const double y = m.balls.pos[i].y();
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

void Platens::drive(Model& m, const SpecimenGeometry& g, double v) const {
  const Vec3 e = unit_axis(g.axis);
  m.walls[static_cast<std::size_t>(top_)].velocity = -v * e;
  m.walls[static_cast<std::size_t>(bottom_)].velocity = v * e;
}

double Platens::separation(const Model& m, int axis) const {
  return m.walls[static_cast<std::size_t>(top_)].center[axis] -
         m.walls[static_cast<std::size_t>(bottom_)].center[axis];
}

double Platens::force(const Model& m, int axis) const {
  return 0.5 * (m.walls[static_cast<std::size_t>(top_)].force[axis] -
                m.walls[static_cast<std::size_t>(bottom_)].force[axis]);
}

double Platens::imbalance(const Model& m, int axis) const {
  const double ft = m.walls[static_cast<std::size_t>(top_)].force[axis];
  const double fb = m.walls[static_cast<std::size_t>(bottom_)].force[axis];
  return std::abs(ft) + std::abs(fb) > 0 ? std::abs(ft + fb) / (std::abs(ft) + std::abs(fb)) : 0.0;
}

void Platens::save(nlohmann::json& state) const {
  state["top"] = top_;
  state["bottom"] = bottom_;
}

void Platens::restore(const nlohmann::json& state, const std::string& file, const Model& m) {
  JsonFieldReader r{state, file};
  r("top", top_), r("bottom", bottom_);
  const auto walls = static_cast<std::int64_t>(m.walls.size());
  if (!(top_ >= 0 && top_ < walls && bottom_ >= 0 && bottom_ < walls))
    corrupt(file, "platen wall");
}

void Grips::mount(Model& m, const SpecimenGeometry& g, const LinearProps&,
                  const std::string& file) {
  const double reach = fraction_ * g.height0;
  for (std::size_t i = 0; i < m.balls.size(); ++i) {
    const double z = m.balls.pos[i][g.axis];
    if (z - g.lo[g.axis] <= reach)
      bottom_.push_back(static_cast<std::int32_t>(i));
    else if (g.hi[g.axis] - z <= reach)
      top_.push_back(static_cast<std::int32_t>(i));
  }
  if (top_.empty() || bottom_.empty())
    throw InputError(file + ": key 'loading.grip_fraction': a grip holds no grains");
  if (!m.clumps.empty())
    throw InputError(file + ": key 'test': the direct-tension grips hold single grains; this "
                            "specimen has clumps (not supported yet)");
  for (const auto* list : {&top_, &bottom_})
    for (std::int32_t i : *list) {
      const auto k = static_cast<std::size_t>(i);
      m.balls.fixity[k] = kAllDofs;
      m.balls.vel[k].setZero();
      m.balls.spin[k].setZero();
    }
}

void Grips::drive(Model& m, const SpecimenGeometry& g, double v) const {
  const Vec3 e = unit_axis(g.axis);
  for (std::int32_t i : top_)
    m.balls.vel[static_cast<std::size_t>(i)] = v * e;
  for (std::int32_t i : bottom_)
    m.balls.vel[static_cast<std::size_t>(i)] = -v * e;
}

double Grips::separation(const Model& m, int axis) const {
  double zt = 0, zb = 0;
  for (std::int32_t i : top_)
    zt += m.balls.pos[static_cast<std::size_t>(i)][axis];
  for (std::int32_t i : bottom_)
    zb += m.balls.pos[static_cast<std::size_t>(i)][axis];
  return zt / static_cast<double>(top_.size()) - zb / static_cast<double>(bottom_.size());
}

double Grips::force(const Model& m, int axis) const {
  double ft = 0, fb = 0;
  for (std::int32_t i : top_)
    ft -= m.balls.force[static_cast<std::size_t>(i)][axis];
  for (std::int32_t i : bottom_)
    fb += m.balls.force[static_cast<std::size_t>(i)][axis];
  return 0.5 * (ft + fb);
}

void Grips::save(nlohmann::json& state) const {
  state["grip_top"] = top_;
  state["grip_bottom"] = bottom_;
}

void Grips::restore(const nlohmann::json& state, const std::string& file, const Model& m) {
  JsonFieldReader r{state, file};
  r("grip_top", top_), r("grip_bottom", bottom_);
  if (top_.empty() || bottom_.empty())
    corrupt(file, "grips");
  const auto balls = static_cast<std::int32_t>(m.balls.size());
  for (const auto* list : {&top_, &bottom_})
    for (std::int32_t i : *list)
      if (i < 0 || i >= balls)
        corrupt(file, "grain index");
}

} // namespace rocklab
