#include "materials/genesis.hpp"

#include "core/servo.hpp"
#include "io/json_input.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <random>
#include <sstream>
#include <stdexcept>

namespace rocklab {

namespace {

constexpr double kPi = std::numbers::pi;

double uniform01(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

double normal(std::mt19937_64& rng, const Distribution& d) {
  if (d.sd <= 0)
    return d.mean;
  // Box-Muller from our own uniform draws (portable, unlike std::normal_distribution).
  const double u1 = std::max(uniform01(rng), 1e-300), u2 = uniform01(rng);
  return std::max(0.0, d.mean + d.sd * std::sqrt(-2 * std::log(u1)) * std::cos(2 * kPi * u2));
}

double grain_volume(int dim, double r) {
  return dim == 2 ? kPi * r * r : 4.0 / 3.0 * kPi * r * r * r;
}

// A circular (2D) or cylindrical (3D, axis z, unbounded along it) wall of radius r.
Wall round_wall(double r) {
  Wall w;
  w.name = "vessel.lateral";
  w.cylinder_radius = r;
  w.half_height = 0;
  w.center = Vec3::Zero();
  w.axis = Vec3::UnitZ();
  w.update_bounds();
  return w;
}

struct Servo {
  std::size_t wall;
  Vec3 n_in = Vec3::Zero(); ///< planar walls: inward normal
  bool radial = false;
};

struct Vessel {
  int dim;
  SpecimenShape shape;
  std::vector<Servo> servos;
  double radius(const Model& m, const Servo& s) const { return m.walls[s.wall].cylinder_radius; }
  // Current extent along axis a between the two planar walls normal to it.
  double extent(const Model& m, int axis) const {
    double lo = 0, hi = 0;
    for (const Servo& s : servos)
      if (!s.radial && std::abs(s.n_in[axis]) > 0.5) {
        const double c = m.walls[s.wall].center[axis];
        (s.n_in[axis] > 0 ? lo : hi) = c;
      }
    return hi - lo;
  }
  double lateral_radius(const Model& m) const {
    for (const Servo& s : servos)
      if (s.radial)
        return radius(m, s);
    return 0;
  }
  double volume(const Model& m) const {
    switch (shape) {
    case SpecimenShape::Rectangle:
      return extent(m, 0) * extent(m, 1);
    case SpecimenShape::Prism:
      return extent(m, 0) * extent(m, 1) * extent(m, 2);
    case SpecimenShape::Disk2D: {
      const double r = lateral_radius(m);
      return kPi * r * r;
    }
    default: {
      const double r = lateral_radius(m);
      return kPi * r * r * extent(m, 2);
    }
    }
  }
  double area(const Model& m, const Servo& s) const {
    if (s.radial) {
      const double r = radius(m, s);
      return 2 * kPi * r * (dim == 2 ? 1.0 : extent(m, 2));
    }
    const int axis = std::abs(s.n_in.x()) > 0.5 ? 0 : (std::abs(s.n_in.y()) > 0.5 ? 1 : 2);
    if (shape == SpecimenShape::Cylinder || shape == SpecimenShape::Disk3D) {
      const double r = lateral_radius(m);
      return kPi * r * r;
    }
    double a = 1;
    for (int d = 0; d < dim; ++d)
      if (d != axis)
        a *= extent(m, d);
    return a;
  }
  // Distance of a wall from the vessel centre (its radius for the round wall) [m].
  double half_extent(const Model& m, const Servo& s) const {
    return s.radial ? radius(m, s) : std::abs(m.walls[s.wall].center.dot(s.n_in));
  }
  // Compressive stress on a wall [Pa].
  double stress(const Model& m, const Servo& s) const {
    const Wall& w = m.walls[s.wall];
    const double f = s.radial ? w.radial_force : -w.force.dot(s.n_in);
    return f / area(m, s);
  }
};

// The vessel of the card's specimen shape, every length multiplied by `scale`.
Vessel make_vessel(Model& m, const MaterialCard& card, double scale) {
  Vessel v;
  v.dim = card.dim;
  v.shape = card.vessel.shape;
  const Vec3 L = card.vessel.size * scale;
  const double big = 1.5 * L.maxCoeff();
  auto add_plane = [&](const std::string& name, const Vec3& p, const Vec3& n) {
    m.walls.push_back(plane_wall(card.dim, name, p, n, big));
    v.servos.push_back({m.walls.size() - 1, n, false});
  };
  switch (card.vessel.shape) {
  case SpecimenShape::Rectangle:
  case SpecimenShape::Prism: {
    const char* names[3] = {"x", "y", "z"};
    for (int d = 0; d < card.dim; ++d)
      for (int side = 0; side < 2; ++side) {
        Vec3 p = Vec3::Zero(), n = Vec3::Zero();
        p[d] = side ? 0.5 * L[d] : -0.5 * L[d];
        n[d] = side ? -1 : 1;
        add_plane(std::string("vessel.") + names[d] + (side ? "max" : "min"), p, n);
      }
    break;
  }
  case SpecimenShape::Disk2D:
  case SpecimenShape::Cylinder:
  case SpecimenShape::Disk3D: {
    const double h = card.dim == 3 ? L.y() : 0;
    m.walls.push_back(round_wall(0.5 * L.x()));
    v.servos.push_back({m.walls.size() - 1, Vec3::Zero(), true});
    if (card.dim == 3) {
      add_plane("vessel.bottom", Vec3(0, 0, -0.5 * h), Vec3::UnitZ());
      add_plane("vessel.top", Vec3(0, 0, 0.5 * h), -Vec3::UnitZ());
    }
    break;
  }
  }
  return v;
}

std::vector<double> sample_radii(const MaterialCard& c, double grain_volume_target,
                                 std::mt19937_64& rng) {
  std::vector<double> r;
  double vol = 0;
  while (vol < grain_volume_target) {
    double radius;
    if (c.sieve.empty()) {
      radius = c.r_min + (c.r_max - c.r_min) * uniform01(rng);
    } else {
      // Diameter drawn by mass from the sieve curve, then thinned by (d_min/d)^dim so the
      // number of grains per size follows the mass fractions.
      for (;;) {
        const double u = uniform01(rng);
        std::size_t k = 1;
        while (k + 1 < c.sieve.size() && c.sieve[k].second < u)
          ++k;
        const auto [d0, f0] = c.sieve[k - 1];
        const auto [d1, f1] = c.sieve[k];
        const double d = f1 > f0 ? d0 + (d1 - d0) * (u - f0) / (f1 - f0) : d1;
        if (uniform01(rng) <= std::pow(c.sieve.front().first / d, c.dim)) {
          radius = 0.5 * d;
          break;
        }
      }
    }
    r.push_back(radius);
    vol += grain_volume(c.dim, radius);
  }
  // Scale so the grains fill exactly (1 - n) of the vessel.
  const double f = std::pow(grain_volume_target / vol, 1.0 / c.dim);
  for (double& x : r)
    x *= f;
  return r;
}

double max_overlap_ratio(const Model& m) {
  double worst = 0;
  for (const Contact& c : m.contacts()) {
    if (c.kind != ContactKind::BallBall || c.gap >= 0)
      continue;
    const double r = std::min(m.balls.radius[static_cast<std::size_t>(c.end1)],
                              m.balls.radius[static_cast<std::size_t>(c.end2)]);
    worst = std::max(worst, -c.gap / r);
  }
  return worst;
}

double grain_volume_sum(const Model& m) {
  double v = 0;
  for (double r : m.balls.radius)
    v += grain_volume(m.settings.dim, r);
  return v;
}

} // namespace

nlohmann::json GenesisReport::to_json() const {
  nlohmann::json walls = nlohmann::json::object();
  for (const auto& [name, s] : wall_stress)
    walls[name] = s;
  return {{"units", "SI"},
          {"grains", grains},
          {"floaters", floaters},
          {"specimen", shape_json(shape, dim)},
          {"porosity_target", porosity_target},
          {"porosity_packed", porosity_packed},
          {"porosity_installed", porosity_installed},
          {"porosity", porosity},
          {"packing_friction", packing_friction},
          {"coordination_number", coordination},
          {"contacts",
           {{"total", contacts},
            {"flatjoint_bonded", fj_bonded},
            {"flatjoint_gapped", fj_gapped},
            {"flatjoint_slit", fj_slit},
            {"linearpbond_bonded", pb_bonded},
            {"contactbond_bonded", cb_bonded},
            {"clumps", clumps},
            {"linear", linear},
            {"smoothjoint", smoothjoint}}},
          {"installation_pressure_Pa", pressure},
          {"wall_stress_Pa", walls},
          {"residual_mean_stress_Pa", residual_mean_stress},
          {"steps",
           {{"packing", steps_packing},
            {"installation", steps_installation},
            {"release", steps_release}}},
          {"seconds", seconds}};
}

GenesisResult run_genesis(const MaterialCard& card,
                          const std::function<void(const std::string&)>& progress,
                          const std::atomic<bool>* interrupt) {
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  auto say = [&](const std::string& s) {
    if (progress)
      progress(s);
  };
  auto out = std::make_unique<Model>();
  Model& m = *out;
  GenesisReport rep;
  const int dim = card.dim;
  m.settings.dim = dim;
  m.settings.local_damping = 0.7;
  m.settings.gravity = Vec3::Zero();
  m.settings.slip_events = false; // nobody reads them during genesis
  std::mt19937_64 rng(card.seed);

  const double V0 = card.vessel.volume(dim);
  std::vector<double> radii = sample_radii(card, (1 - card.porosity) * V0, rng);
  const double r_avg = [&] {
    double s = 0;
    for (double r : radii)
      s += r;
    return s / static_cast<double>(radii.size());
  }();
  // The cloud is at the cloud porosity: boundary contraction puts the full-size grains into a
  // vessel enlarged by 1/shrink; grain scaling shrinks the grains by `shrink` inside the vessel.
  const double shrink = std::pow((1 - card.cloud_porosity) / (1 - card.porosity), 1.0 / dim);
  const bool contraction = card.packing_method == MaterialCard::Packing::Contraction;
  const double vessel_scale = contraction ? 1.0 / shrink : 1.0;
  const double grain_scale = contraction ? 1.0 : shrink;
  Vessel vessel = make_vessel(m, card, vessel_scale);
  const int grains = m.group_index("grains");
  const bool round = card.vessel.shape == SpecimenShape::Disk2D ||
                     card.vessel.shape == SpecimenShape::Cylinder ||
                     card.vessel.shape == SpecimenShape::Disk3D;
  const Vec3& L = card.vessel.size;
  const Vec3 half =
      vessel_scale * (round ? Vec3(0.5 * L.x(), 0.5 * L.x(), dim == 3 ? 0.5 * L.y() : 0.0)
                            : Vec3(0.5 * L.x(), 0.5 * L.y(), dim == 3 ? 0.5 * L.z() : 0.0));
  std::vector<Vec3> cloud;
  for (std::size_t i = 0; i < radii.size(); ++i) {
    const double r = radii[i] * grain_scale;
    // Uniform in the shape's bounding box, kept when the grain lies inside the shape.
    Vec3 x = Vec3::Zero();
    for (int attempt = 0;; ++attempt) {
      for (int d = 0; d < dim; ++d)
        x[d] = (2 * uniform01(rng) - 1) * half[d];
      if (card.vessel.contains(x / vessel_scale, r / vessel_scale) || attempt > 10000)
        break;
    }
    cloud.push_back(x);
  }
  // Number the grains along a Morton (Z-order) curve of their cells, so that grains near each
  // other in space are near each other in memory: the contact loop and the force sum then read
  // mostly cached data (the random cloud order made them ~2x slower on big specimens).
  {
    const double cell = 2 * r_avg * grain_scale;
    auto spread = [](std::uint64_t v) { // 21 bits -> every third bit
      v &= 0x1fffff;
      v = (v | v << 32) & 0x1f00000000ffffULL;
      v = (v | v << 16) & 0x1f0000ff0000ffULL;
      v = (v | v << 8) & 0x100f00f00f00f00fULL;
      v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
      v = (v | v << 2) & 0x1249249249249249ULL;
      return v;
    };
    std::vector<std::pair<std::uint64_t, std::size_t>> order(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      std::uint64_t key = 0;
      for (int d = 0; d < dim; ++d)
        key |= spread(static_cast<std::uint64_t>((cloud[i][d] + half[d]) / cell)) << d;
      order[i] = {key, i};
    }
    std::stable_sort(order.begin(), order.end());
    std::vector<double> sorted_radii(radii.size());
    for (std::size_t k = 0; k < order.size(); ++k) {
      const std::size_t i = order[k].second;
      sorted_radii[k] = radii[i];
      m.balls.add(dim, static_cast<std::int64_t>(k + 1), cloud[i], radii[i] * grain_scale,
                  card.density, grains);
    }
    radii = std::move(sorted_radii);
  }
  // Packing contacts: linear springs with the card's stiffness at the mean size; frictionless
  // for the cloud relaxation, then the packing friction between grains. Vessel walls stay
  // frictionless.
  LinearProps pack;
  if (card.linear.emod > 0) {
    const double area = dim == 2 ? 2 * r_avg : kPi * r_avg * r_avg;
    pack.kn = area * card.linear.emod / (2 * r_avg);
    pack.ks = card.linear.kratio > 0 ? pack.kn / card.linear.kratio : 0;
  } else {
    pack.kn = card.linear.kn;
    pack.ks = card.linear.ks;
  }
  pack.fric = 0;
  // Compaction runs with springs soft enough that the pressure strains them by
  // `compaction_strain` (the rearrangement takes ~sqrt(E*/p) steps, so stiff rock contacts
  // would make it slow); the card's stiffness is installed once the porosity is locked.
  const LinearProps stiff = pack;
  {
    const double area = dim == 2 ? 2 * r_avg : kPi * r_avg * r_avg;
    const double e_equiv = pack.kn * 2 * r_avg / area;
    const double f = std::min(1.0, card.pressure / (card.compaction_strain * e_equiv));
    pack.kn *= f;
    pack.ks *= f;
  }
  ModelRule bb, bf;
  bb.props = pack;
  bf.ball_facet = true;
  LinearProps pack_wall = pack;
  pack_wall.kn *= 2; // L = R for a facet
  pack_wall.ks *= 2;
  bf.props = pack_wall;
  m.rules = {bb, bf};
  m.settings.margin = std::max(0.05 * r_avg, card.install_gap);
  m.settings.overlap_check = false; // a cloud overlaps by design
  m.initialize();

  auto run_until = [&](const char* phase, std::int64_t check, auto&& done) {
    const std::int64_t start = m.step();
    while (!done()) {
      if (m.step() - start > card.max_cycles)
        throw std::runtime_error(card.file + ": genesis phase '" + phase +
                                 "' did not converge in " + std::to_string(card.max_cycles) +
                                 " cycles (key 'packing.max_cycles')");
      m.cycle(check);
      m.clear_events();
      if (interrupt && interrupt->load())
        throw std::runtime_error("interrupted");
    }
    return m.step() - start;
  };
  say("relaxing the grain cloud");
  rep.steps_packing += run_until("cloud relaxation", 50,
                                 [&] { return max_overlap_ratio(m) <= card.max_overlap_ratio; });
  if (!contraction)
    for (std::size_t i = 0; i < m.balls.size(); ++i)
      m.balls.set_radius(i, radii[i], dim);
  m.settings.overlap_check = true;

  // Servo control of every vessel wall toward a target stress: the wall speed closes half the
  // stress error per step (0.5 A / (sum k dt) x error), capped so the vessel contracts at one
  // strain rate (the cap is proportional to the wall's distance from the centre).
  const double p = card.pressure;
  double largest_half = 0;
  for (const Servo& s : vessel.servos)
    largest_half = std::max(largest_half, vessel.half_extent(m, s));
  double speed_cap = 0.01;  // largest wall displacement per step / mean radius
  std::vector<double> ksum; // reused by every servo step
  auto servo_step = [&](double target) {
    wall_stiffness_sums(m, ksum);
    const double dt = std::max(m.timestep(), 1e-12);
    for (const Servo& s : vessel.servos) {
      const double vmax = speed_cap * r_avg / dt * vessel.half_extent(m, s) / largest_half;
      const double v = servo_velocity(0.5, vessel.area(m, s), ksum[s.wall], dt,
                                      target - vessel.stress(m, s), vmax);
      Wall& w = m.walls[s.wall];
      if (s.radial)
        w.radial_velocity = -v;
      else
        w.velocity = v * s.n_in;
    }
  };
  auto stresses_within = [&](double target, double tol) {
    for (const Servo& s : vessel.servos)
      if (std::abs(vessel.stress(m, s) - target) > tol * target)
        return false;
    return true;
  };
  auto porosity_now = [&] { return 1 - grain_volume_sum(m) / vessel.volume(m); };

  // Compaction at the installation pressure with friction control (as in YADE's triaxial
  // compaction): the servo-controlled walls compact grains with the packing friction; while
  // the packing at pressure is looser than the target the friction is lowered step by step; at
  // the target the packing friction locks the structure and the walls hold the pressure until
  // equilibrium.
  say("compacting to the target porosity at the installation pressure");
  auto set_packing_friction = [&](double f) {
    std::get<LinearProps>(m.rules[0].props).fric = f;
    m.set_property(model_kind<Linear>, "fric", f, ContactSelect::BallBall);
  };
  auto install_card_stiffness = [&] {
    LinearProps& b = std::get<LinearProps>(m.rules[0].props);
    LinearProps& w = std::get<LinearProps>(m.rules[1].props);
    b.kn = stiff.kn;
    b.ks = stiff.ks;
    w.kn = 2 * stiff.kn;
    w.ks = 2 * stiff.ks;
    m.set_property(model_kind<Linear>, "kn", b.kn, ContactSelect::BallBall);
    m.set_property(model_kind<Linear>, "ks", b.ks, ContactSelect::BallBall);
    m.set_property(model_kind<Linear>, "kn", w.kn, ContactSelect::BallFacet);
    m.set_property(model_kind<Linear>, "ks", w.ks, ContactSelect::BallFacet);
  };
  {
    const std::int64_t start = m.step();
    const std::int64_t chunk = 100;
    const double tol_n = card.porosity_tolerance;
    bool frozen = false;
    std::int64_t frozen_at = 0, window_at = m.step(), decrements = 0;
    double mu = card.packing_friction;
    set_packing_friction(mu);
    double n_window = 1.0;
    for (;;) {
      for (std::int64_t k = 0; k < chunk; ++k) {
        servo_step(p);
        m.cycle(1);
      }
      m.clear_events();
      if (interrupt && interrupt->load())
        throw std::runtime_error("interrupted");
      const double n = porosity_now();
      const double ratio = m.mean_unbalanced_force_ratio();
      const bool settled =
          stresses_within(p, card.pressure_tolerance) && ratio <= card.equilibrium_ratio;
      // Frictionless compaction has stalled when, at pressure, the porosity moved less than a
      // twentieth of the tolerance over the last 5000 steps.
      bool stalled = false;
      if (m.step() - window_at >= 5000) {
        stalled = stresses_within(p, 0.05) && n_window - n < 0.05 * tol_n;
        n_window = n;
        window_at = m.step();
      }
      if ((m.step() - start) % 5000 < chunk) {
        std::ostringstream msg;
        msg << (frozen ? "installing" : "compacting") << ": step " << m.step() << ", porosity " << n
            << ", unbalanced-force ratio " << ratio << ", wall stresses [Pa]";
        for (const Servo& s : vessel.servos)
          msg << " " << vessel.stress(m, s);
        say(msg.str());
      }
      const bool at_pressure = stresses_within(p, 0.1);
      if (!frozen && n <= card.porosity + 0.25 * tol_n && at_pressure) {
        // Target reached: lock the structure with the packing friction so that it stops
        // creeping toward its frictionless density; the grains come to rest in the held vessel,
        // then the walls hold the pressure.
        if (decrements == 0 && n < card.porosity - tol_n) {
          std::ostringstream msg;
          msg << card.file << ": key 'porosity': the target " << card.porosity
              << " is looser than the porosity " << n << " that a packing with friction "
              << card.packing_friction
              << " reaches at the installation pressure; raise 'packing.friction'";
          throw InputError(msg.str());
        }
        frozen = true;
        frozen_at = m.step();
        rep.porosity_packed = n;
        rep.packing_friction = mu;
        set_packing_friction(card.packing_friction);
        install_card_stiffness();
        for (std::size_t i = 0; i < m.balls.size(); ++i) {
          m.balls.vel[i].setZero();
          m.balls.spin[i].setZero();
        }
        for (Wall& w : m.walls) {
          w.velocity.setZero();
          w.radial_velocity = 0;
        }
        run_until("settling the locked packing", 50,
                  [&] { return m.mean_unbalanced_force_ratio() <= 1e-2; });
        speed_cap = 0.001;
      } else if (!frozen && at_pressure && mu > 0 && n > card.porosity) {
        // Too loose at pressure: lower the grain friction a little (the packing follows).
        mu = mu > 0.01 * card.packing_friction ? 0.97 * mu : 0.0;
        set_packing_friction(mu);
        ++decrements;
      } else if (!frozen && mu == 0 && (settled || stalled)) {
        std::ostringstream msg;
        msg << card.file << ": key 'porosity': the target " << card.porosity
            << " is below the porosity " << n
            << " that a frictionless packing of these grains reaches at the installation "
               "pressure in this vessel; raise the target or widen the size distribution";
        throw InputError(msg.str());
      }
      if (frozen && settled)
        break;
      if (m.step() - start > card.max_cycles)
        throw std::runtime_error(
            card.file + ": the vessel did not reach the installation pressure " +
            std::to_string(p) + " Pa at the target porosity in " + std::to_string(card.max_cycles) +
            " cycles (key 'packing.max_cycles')");
    }
    rep.steps_packing += frozen_at - start;
    rep.steps_installation = m.step() - frozen_at;
  }
  rep.porosity_target = card.porosity;
  rep.porosity = rep.porosity_installed = porosity_now();
  for (Wall& w : m.walls) {
    w.velocity.setZero();
    w.radial_velocity = 0;
  }
  for (const Servo& s : vessel.servos)
    rep.wall_stress.emplace_back(m.walls[s.wall].name, vessel.stress(m, s));
  rep.pressure = p;
  const double V_installed = vessel.volume(m);
  rep.shape.shape = card.vessel.shape;
  switch (card.vessel.shape) {
  case SpecimenShape::Rectangle:
    rep.shape.size = Vec3(vessel.extent(m, 0), vessel.extent(m, 1), 0);
    break;
  case SpecimenShape::Prism:
    rep.shape.size = Vec3(vessel.extent(m, 0), vessel.extent(m, 1), vessel.extent(m, 2));
    break;
  case SpecimenShape::Disk2D:
    rep.shape.size = Vec3(2 * vessel.lateral_radius(m), 0, 0);
    break;
  case SpecimenShape::Cylinder:
  case SpecimenShape::Disk3D:
    rep.shape.size = Vec3(2 * vessel.lateral_radius(m), vessel.extent(m, 2), 0);
    break;
  }
  if (card.cut)
    rep.shape = *card.cut;

  // Floaters: fewer than 3 (3D) or 2 (2D) force-carrying contacts.
  auto count_contacts = [&]() {
    std::vector<int> n(m.balls.size(), 0);
    for (std::size_t ci = 0; ci < m.contacts().size(); ++ci) {
      const Contact& c = m.contacts()[ci];
      if (m.contact_outputs()[ci].force == Vec3::Zero())
        continue;
      ++n[static_cast<std::size_t>(c.end1)];
      if (c.kind == ContactKind::BallBall)
        ++n[static_cast<std::size_t>(c.end2)];
    }
    return n;
  };
  {
    const std::vector<int> n = count_contacts();
    std::vector<bool> floater(m.balls.size(), false);
    for (std::size_t i = 0; i < n.size(); ++i)
      floater[i] = n[i] < (dim == 3 ? 3 : 2);
    rep.floaters = std::count(floater.begin(), floater.end(), true);
    std::int64_t bb = 0;
    for (std::size_t ci = 0; ci < m.contacts().size(); ++ci) {
      const Contact& c = m.contacts()[ci];
      if (c.kind == ContactKind::BallBall && m.contact_outputs()[ci].force != Vec3::Zero() &&
          !floater[static_cast<std::size_t>(c.end1)] && !floater[static_cast<std::size_t>(c.end2)])
        ++bb;
    }
    const double live = static_cast<double>(m.balls.size()) - static_cast<double>(rep.floaters);
    rep.coordination = live > 0 ? 2.0 * static_cast<double>(bb) / live : 0;
    if (card.eliminate_floaters && rep.floaters > 0)
      m.remove_balls(floater);
  }

  if (card.clump_max > 1) {
    // Clumps (thesis Appendix B): in a seeded random order, each free grain takes up to
    // clump_max - 1 free grains it touches (in contact order) and the group becomes one rigid
    // body with the grains as pebbles, mass and inertia of their union.
    say("joining grains into clumps");
    const std::size_t n = m.balls.size();
    std::vector<std::vector<std::int32_t>> touching(n);
    for (std::size_t ci = 0; ci < m.contacts().size(); ++ci) {
      const Contact& c = m.contacts()[ci];
      if (c.kind == ContactKind::BallBall && c.gap <= 0) {
        touching[static_cast<std::size_t>(c.end1)].push_back(c.end2);
        touching[static_cast<std::size_t>(c.end2)].push_back(c.end1);
      }
    }
    std::vector<std::size_t> order(n);
    for (std::size_t i = 0; i < n; ++i)
      order[i] = i;
    for (std::size_t i = n; i > 1; --i)
      std::swap(order[i - 1],
                order[static_cast<std::size_t>(uniform01(rng) * static_cast<double>(i))]);
    std::vector<bool> taken(n, false), remove(n, false);
    std::vector<std::vector<std::size_t>> groups;
    for (std::size_t i : order) {
      if (taken[i])
        continue;
      std::vector<std::size_t> g{i};
      taken[i] = true;
      for (std::int32_t j : touching[i]) {
        if (static_cast<int>(g.size()) >= card.clump_max)
          break;
        if (!taken[static_cast<std::size_t>(j)]) {
          taken[static_cast<std::size_t>(j)] = true;
          g.push_back(static_cast<std::size_t>(j));
        }
      }
      if (g.size() > 1) {
        for (std::size_t k : g)
          remove[k] = true;
        groups.push_back(std::move(g));
      }
    }
    struct Pending {
      std::vector<Pebble> pebbles;
      Vec3 vel;
      int group;
      std::vector<std::int64_t> ids;
    };
    std::vector<Pending> pending;
    for (const auto& g : groups) {
      Pending p;
      p.vel = Vec3::Zero();
      for (std::size_t k : g) {
        p.pebbles.push_back({m.balls.pos[k], m.balls.radius[k]});
        p.vel += m.balls.vel[k] / static_cast<double>(g.size());
        p.ids.push_back(m.balls.id[k]);
      }
      p.group = m.balls.group[g[0]];
      pending.push_back(std::move(p));
    }
    m.remove_balls(remove);
    std::int64_t next_id = 1;
    for (std::int64_t id : m.balls.id)
      next_id = std::max(next_id, id + 1);
    for (const Pending& p : pending)
      for (std::int64_t id : p.ids)
        next_id = std::max(next_id, id + 1);
    std::int64_t clump_id = 1;
    for (const Pending& p : pending) {
      m.add_clump(p.pebbles, card.density, p.group, clump_id++, next_id, p.vel, Vec3::Zero());
      next_id += static_cast<std::int64_t>(p.pebbles.size());
    }
    m.set_margin(m.margin()); // detect the contacts of the new pebbles
    m.cycle(1);
    rep.clumps = static_cast<std::int64_t>(m.clumps.size());
  }

  // Finalization: bonds at grain-grain contacts with gap <= g_i, linear elsewhere.
  say("finalizing");
  m.set_margin(std::max(m.margin(), card.install_gap * 1.01));
  std::vector<std::size_t> candidates;
  for (std::size_t ci = 0; ci < m.contacts().size(); ++ci) {
    const Contact& c = m.contacts()[ci];
    if (c.kind == ContactKind::BallBall && c.gap <= card.install_gap)
      candidates.push_back(ci);
  }
  for (std::size_t i = candidates.size(); i > 1; --i) // seeded Fisher-Yates shuffle
    std::swap(candidates[i - 1],
              candidates[static_cast<std::size_t>(uniform01(rng) * static_cast<double>(i))]);
  const std::size_t N = candidates.size();
  const std::size_t n_bonded =
      static_cast<std::size_t>(std::llround(card.frac_bonded * static_cast<double>(N)));
  const std::size_t n_gapped =
      std::min(N - n_bonded,
               static_cast<std::size_t>(std::llround(card.frac_gapped * static_cast<double>(N))));
  std::vector<bool> is_bond(m.contacts().size(), false);
  // A bonded model (parallel or contact bond) on the card's linear component, bonded now.
  auto install_bond = [&](std::size_t ci, auto props, std::int64_t& count) {
    const double rgap = props.linear.rgap;
    props.linear = card.linear;
    props.linear.rgap = rgap;
    props.bond = true;
    props.bond_gap_lo = -1e300;
    props.bond_gap_hi = 1e300; // the candidate test above already applied g <= g_i
    m.replace_contact_model(ci, props);
    ++count;
  };
  for (std::size_t k = 0; k < N; ++k) {
    const std::size_t ci = candidates[k];
    is_bond[ci] = true;
    if (card.bonding == MaterialCard::Bonding::FlatJoint) {
      FlatJointProps fj = card.fj;
      fj.fj_ten = normal(rng, card.fj_ten);
      fj.fj_coh = normal(rng, card.fj_coh);
      if (k < n_bonded) {
        fj.bond = true;
        fj.fj_gap0 = 0;
        ++rep.fj_bonded;
      } else if (k < n_bonded + n_gapped) {
        fj.bond = false;
        fj.fj_gap0 = std::max(normal(rng, card.gapped_gap), 1e-12 * r_avg);
        ++rep.fj_gapped;
      } else {
        fj.bond = false;
        fj.fj_gap0 = 0;
        ++rep.fj_slit;
      }
      m.replace_contact_model(ci, fj);
    } else if (card.bonding == MaterialCard::Bonding::ParallelBond) {
      LinearPBondProps pb = card.pb;
      pb.pb_ten = normal(rng, card.pb_ten);
      pb.pb_coh = normal(rng, card.pb_coh);
      install_bond(ci, pb, rep.pb_bonded);
    } else if (card.bonding == MaterialCard::Bonding::ContactBond) {
      ContactBondProps cb;
      // A point bond made across an open gap would start in tension (its normal force is
      // kn (g - g_r)); the reference gap makes the bonded gap the contact's rest state.
      cb.linear.rgap = std::max(m.contacts()[ci].gap, 0.0);
      cb.cb_tenf = normal(rng, card.cb_tenf);
      cb.cb_shearf = normal(rng, card.cb_shearf);
      install_bond(ci, cb, rep.cb_bonded);
    } else {
      is_bond[ci] = false;
    }
  }
  for (std::size_t ci = 0; ci < m.contacts().size(); ++ci)
    if (!is_bond[ci]) {
      LinearProps lp = card.linear;
      m.replace_contact_model(ci, lp);
    }
  ModelRule new_bb, new_bf;
  new_bb.props = card.linear;
  new_bf.ball_facet = true;
  new_bf.props = card.linear;
  m.rules = {new_bb, new_bf};

  // Release: unload the vessel quasi-statically, remove it, relax the locked-in stresses.
  say("releasing the vessel");
  {
    const std::int64_t start = m.step();
    const int ramp = 20;
    for (int k = ramp - 1; k >= 0; --k) {
      const double target = p * k / ramp;
      for (int c = 0; c < 100; ++c) {
        servo_step(std::max(target, 1e-6 * p));
        m.cycle(1);
      }
      m.clear_events();
      if (interrupt && interrupt->load())
        throw std::runtime_error("interrupted");
    }
    for (Wall& w : m.walls) {
      w.velocity.setZero();
      w.radial_velocity = 0;
    }
    std::vector<bool> all(m.walls.size(), true);
    m.remove_walls(all);
    run_until("release", 50,
              [&] { return m.mean_unbalanced_force_ratio() <= card.equilibrium_ratio; });
    if (card.cut) {
      std::vector<bool> outside(m.balls.size());
      for (std::size_t i = 0; i < m.balls.size(); ++i)
        outside[i] = !card.cut->contains(m.balls.pos[i]);
      m.remove_balls(outside);
      run_until("release after cutting", 50,
                [&] { return m.mean_unbalanced_force_ratio() <= card.equilibrium_ratio; });
    }
    rep.steps_release = m.step() - start;
  }
  const double V_final = card.cut ? card.cut->volume(dim) : V_installed;
  if (card.cut) // grains whose centres lie inside count whole: an unbiased volume fraction
    rep.porosity = 1 - grain_volume_sum(m) / V_final;
  {
    const Eigen::Matrix3d s = m.average_stress(V_final);
    rep.residual_mean_stress = -s.trace() / dim;
  }

  // Joint sets: contacts straddling a joint plane become smooth joints.
  for (const JointSpec& j : card.joints) {
    const Vec3 n = smoothjoint::joint_normal(dim, j.dip, j.ddir);
    const double extent = card.vessel.size.maxCoeff();
    std::vector<double> offsets{0};
    if (j.spacing > 0)
      for (double o = j.spacing; o < extent; o += j.spacing) {
        offsets.push_back(o);
        offsets.push_back(-o);
      }
    for (std::size_t ci = 0; ci < m.contacts().size(); ++ci) {
      const Contact& c = m.contacts()[ci];
      if (c.kind != ContactKind::BallBall || c.model == model_kind<SmoothJoint>)
        continue;
      const Vec3& a = m.balls.pos[static_cast<std::size_t>(c.end1)];
      const Vec3& b = m.balls.pos[static_cast<std::size_t>(c.end2)];
      for (double o : offsets) {
        const double da = (a - j.point).dot(n) - o, db = (b - j.point).dot(n) - o;
        if ((da < 0) != (db < 0)) {
          m.replace_contact_model(ci, j.props);
          break;
        }
      }
    }
  }

  rep.dim = dim;
  rep.grains = static_cast<std::int64_t>(m.balls.size());
  rep.contacts = static_cast<std::int64_t>(m.contacts().size());
  for (const Contact& c : m.contacts()) {
    rep.linear += c.model == model_kind<Linear>;
    rep.smoothjoint += c.model == model_kind<SmoothJoint>;
  }
  rep.seconds = std::chrono::duration<double>(clock::now() - t0).count();
  return {std::move(out), rep};
}

} // namespace rocklab
