#include "materials/genesis.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <random>
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

Facet facet(std::initializer_list<Vec3> pts) {
  Facet f;
  f.nv = static_cast<int>(pts.size());
  int k = 0;
  for (const Vec3& p : pts)
    f.v[k++] = p;
  return f;
}

// A plane wall through p with inward normal n (square of side `extent`; 2D: a segment).
Wall plane(int dim, const std::string& name, const Vec3& p, const Vec3& n, double extent) {
  Wall w;
  w.name = name;
  const double h = 0.5 * extent;
  if (dim == 2) {
    const Vec3 u(-n.y(), n.x(), 0);
    w.facets.push_back(facet({p - h * u, p + h * u}));
  } else {
    const Vec3 g = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
    const Vec3 u = (g - g.dot(n) * n).normalized(), v = n.cross(u);
    const Vec3 a = p - h * u - h * v, b = p + h * u - h * v, c = p + h * u + h * v,
               d = p - h * u + h * v;
    w.facets = {facet({a, b, c}), facet({a, c, d})};
  }
  w.center = p;
  w.update_bounds();
  return w;
}

// A circular (2D) or cylindrical (3D, axis z, from -h/2 to h/2) wall whose flat faces lie at
// radius r (circumscribed polygon of n sides).
Wall round_wall(int dim, double r, double h, int n) {
  Wall w;
  w.name = "vessel.lateral";
  const double rv = r / std::cos(kPi / n);
  for (int k = 0; k < n; ++k) {
    const double a0 = 2 * kPi * k / n, a1 = 2 * kPi * (k + 1) / n;
    const Vec3 p0(rv * std::cos(a0), rv * std::sin(a0), 0),
        p1(rv * std::cos(a1), rv * std::sin(a1), 0);
    if (dim == 2) {
      w.facets.push_back(facet({p0, p1}));
    } else {
      const Vec3 lo(0, 0, -0.5 * h), hi(0, 0, 0.5 * h);
      w.facets.push_back(facet({p0 + lo, p1 + lo, p1 + hi}));
      w.facets.push_back(facet({p0 + lo, p1 + hi, p0 + hi}));
    }
  }
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
  int sides = 0; // polygon sides of a round wall

  double radius(const Model& m, const Servo& s) const {
    const Vec3 v = m.walls[s.wall].facets[0].v[0];
    return std::hypot(v.x(), v.y()) * std::cos(kPi / sides);
  }
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
  // Compressive stress on a wall [Pa].
  double stress(const Model& m, const Servo& s) const {
    const Wall& w = m.walls[s.wall];
    const double f = s.radial ? w.radial_force : -w.force.dot(s.n_in);
    return f / area(m, s);
  }
};

Vessel make_vessel(Model& m, const MaterialCard& card) {
  Vessel v;
  v.dim = card.dim;
  v.shape = card.vessel.shape;
  const Vec3 L = card.vessel.size;
  const double big = 1.5 * L.maxCoeff();
  auto add_plane = [&](const std::string& name, const Vec3& p, const Vec3& n) {
    m.walls.push_back(plane(card.dim, name, p, n, big));
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
    v.sides = card.dim == 2 ? 96 : 64;
    const double h = card.dim == 3 ? L.y() : 0;
    m.walls.push_back(round_wall(card.dim, 0.5 * L.x(), 1.3 * h, v.sides));
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
          {"porosity_target", porosity_target},
          {"porosity_packed", porosity_packed},
          {"porosity", porosity},
          {"coordination_number", coordination},
          {"contacts",
           {{"total", contacts},
            {"flatjoint_bonded", fj_bonded},
            {"flatjoint_gapped", fj_gapped},
            {"flatjoint_slit", fj_slit},
            {"linearpbond_bonded", pb_bonded},
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
                          const std::function<void(const std::string&)>& progress) {
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
  std::mt19937_64 rng(card.seed);

  Vessel vessel = make_vessel(m, card);
  const double V0 = card.vessel.volume(dim);
  const std::vector<double> radii = sample_radii(card, (1 - card.porosity) * V0, rng);
  const double r_avg = [&] {
    double s = 0;
    for (double r : radii)
      s += r;
    return s / static_cast<double>(radii.size());
  }();
  // Cloud: the same grains shrunk to the cloud porosity, placed at random (overlaps allowed).
  const double shrink = std::pow((1 - card.cloud_porosity) / (1 - card.porosity), 1.0 / dim);
  const int grains = m.group_index("grains");
  for (std::size_t i = 0; i < radii.size(); ++i) {
    const double r = radii[i] * shrink;
    // Uniform in the shape's bounding box, kept when the grain lies inside the shape.
    const Vec3& L = card.vessel.size;
    const bool round = card.vessel.shape == SpecimenShape::Disk2D ||
                       card.vessel.shape == SpecimenShape::Cylinder ||
                       card.vessel.shape == SpecimenShape::Disk3D;
    const Vec3 half = round ? Vec3(0.5 * L.x(), 0.5 * L.x(), dim == 3 ? 0.5 * L.y() : 0.0)
                            : Vec3(0.5 * L.x(), 0.5 * L.y(), dim == 3 ? 0.5 * L.z() : 0.0);
    Vec3 x = Vec3::Zero();
    for (int attempt = 0;; ++attempt) {
      for (int d = 0; d < dim; ++d)
        x[d] = (2 * uniform01(rng) - 1) * half[d];
      if (card.vessel.contains(x, r) || attempt > 10000)
        break;
    }
    m.balls.add(dim, static_cast<std::int64_t>(i + 1), x, r, card.density, grains);
  }
  // Packing contacts: frictionless linear springs with the card's stiffness at the mean size.
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
    }
    return m.step() - start;
  };
  say("relaxing the grain cloud");
  rep.steps_packing += run_until("cloud relaxation", 50,
                                 [&] { return max_overlap_ratio(m) <= card.max_overlap_ratio; });
  // Grain scaling to the target porosity (deep overlaps right after scaling are expected too).
  for (std::size_t i = 0; i < m.balls.size(); ++i)
    m.balls.set_radius(i, radii[i], dim);
  say("packing at the target porosity");
  rep.steps_packing += run_until(
      "packing", 50, [&] { return m.mean_unbalanced_force_ratio() <= card.equilibrium_ratio; });
  rep.porosity_target = card.porosity;
  rep.porosity_packed = 1 - grain_volume_sum(m) / vessel.volume(m);

  // Installation: servo-controlled vessel walls reach the isotropic pressure.
  m.settings.overlap_check = true;
  say("installing the isotropic stress");
  const double p = card.pressure;
  auto servo_step = [&](double target) {
    std::vector<double> ksum(m.walls.size(), 0.0);
    for (std::size_t ci = 0; ci < m.contacts().size(); ++ci)
      if (m.contacts()[ci].kind == ContactKind::BallFacet)
        ksum[static_cast<std::size_t>(m.contacts()[ci].end2)] +=
            m.contact_outputs()[ci].stiff.k_tran;
    const double dt = std::max(m.timestep(), 1e-12);
    const double vmax = 0.01 * r_avg / dt;
    for (const Servo& s : vessel.servos) {
      const double err = target - vessel.stress(m, s); // > 0: push in
      const double A = vessel.area(m, s);
      double v = ksum[s.wall] > 0 ? 0.5 * A / (ksum[s.wall] * dt) * err : vmax;
      v = std::clamp(v, -vmax, vmax);
      Wall& w = m.walls[s.wall];
      if (s.radial)
        w.radial_velocity = -v;
      else
        w.velocity = v * s.n_in;
    }
  };
  auto stresses_ok = [&](double target, double tol) {
    for (const Servo& s : vessel.servos)
      if (std::abs(vessel.stress(m, s) - target) > tol * target)
        return false;
    return true;
  };
  {
    const std::int64_t start = m.step();
    std::int64_t since_check = 0;
    for (;;) {
      servo_step(p);
      m.cycle(1);
      if (++since_check >= 50) {
        since_check = 0;
        if (stresses_ok(p, card.pressure_tolerance) &&
            m.mean_unbalanced_force_ratio() <= card.equilibrium_ratio)
          break;
      }
      if (m.step() - start > card.max_cycles)
        throw std::runtime_error(card.file +
                                 ": the vessel did not reach the installation pressure " +
                                 std::to_string(p) + " Pa in " + std::to_string(card.max_cycles) +
                                 " cycles (key 'packing.max_cycles')");
    }
    rep.steps_installation = m.step() - start;
  }
  for (Wall& w : m.walls) {
    w.velocity.setZero();
    w.radial_velocity = 0;
  }
  for (const Servo& s : vessel.servos)
    rep.wall_stress.emplace_back(m.walls[s.wall].name, vessel.stress(m, s));
  rep.pressure = p;
  const double V_installed = vessel.volume(m);
  rep.porosity = 1 - grain_volume_sum(m) / V_installed;

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
      PBondProps pb = card.pb;
      pb.linear = card.linear;
      pb.pb_ten = normal(rng, card.pb_ten);
      pb.pb_coh = normal(rng, card.pb_coh);
      pb.bond = true;
      pb.bond_gap_lo = -1e300;
      pb.bond_gap_hi = 1e300; // the candidate test above already applied g <= g_i
      m.replace_contact_model(ci, pb);
      ++rep.pb_bonded;
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
  {
    const Eigen::Matrix3d s = m.average_stress(V_final);
    rep.residual_mean_stress = -s.trace() / dim;
  }

  // Joint sets: contacts straddling a joint plane become smooth joints.
  for (const JointSpec& j : card.joints) {
    const Vec3 n = joint_normal(dim, j.dip, j.ddir);
    const double extent = card.vessel.size.maxCoeff();
    std::vector<double> offsets{0};
    if (j.spacing > 0)
      for (double o = j.spacing; o < extent; o += j.spacing) {
        offsets.push_back(o);
        offsets.push_back(-o);
      }
    for (std::size_t ci = 0; ci < m.contacts().size(); ++ci) {
      const Contact& c = m.contacts()[ci];
      if (c.kind != ContactKind::BallBall || c.model == ModelKind::SmoothJoint)
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

  rep.grains = static_cast<std::int64_t>(m.balls.size());
  rep.contacts = static_cast<std::int64_t>(m.contacts().size());
  for (const Contact& c : m.contacts()) {
    rep.linear += c.model == ModelKind::Linear;
    rep.smoothjoint += c.model == ModelKind::SmoothJoint;
  }
  rep.seconds = std::chrono::duration<double>(clock::now() - t0).count();
  return {std::move(out), rep};
}

} // namespace rocklab
