// Clumps (rigid pebble bodies) and group energy tracing (thesis section 3): union mass
// properties, torque-free motion, a one-pebble clump against a ball, and the sharing rule in a
// two-clump rockfall scene like thesis Fig. 4.
#include "helpers.hpp"

#include <cmath>

using namespace rocklab;
using rocklab::test::near_rel;

namespace {

LinearProps linear_props(double kn, double ks, double fric) {
  LinearProps p;
  p.kn = kn;
  p.ks = ks;
  p.fric = fric;
  return p;
}

void add_rule(Model& m, bool ball_facet, const ModelProps& props) {
  ModelRule r;
  r.ball_facet = ball_facet;
  r.props = props;
  m.rules.push_back(r);
}

} // namespace

TEST(Clumps, UnionMassPropertiesExactAndGrid) {
  const double rho = 2600, r = 0.05;
  // One pebble: exactly a ball.
  MassProperties one = union_mass_properties({{Vec3(1, 2, 3), r}}, rho, 3);
  const double m1 = rho * 4.0 / 3.0 * M_PI * r * r * r;
  EXPECT_TRUE(one.exact);
  EXPECT_DOUBLE_EQ(one.mass, m1);
  EXPECT_TRUE(near_rel(one.inertia(0, 0), 0.4 * m1 * r * r, 1e-14));
  EXPECT_TRUE(near_rel(one.inertia(0, 1), 0.0, 1e-14, 1e-30));
  // Two touching spheres: parallel-axis theorem.
  MassProperties two = union_mass_properties({{Vec3(-r, 0, 0), r}, {Vec3(r, 0, 0), r}}, rho, 3);
  EXPECT_TRUE(two.exact);
  EXPECT_TRUE(near_rel(two.inertia(0, 0), 0.8 * m1 * r * r, 1e-12));
  EXPECT_TRUE(near_rel(two.inertia(1, 1), 0.8 * m1 * r * r + 2 * m1 * r * r, 1e-12));
  // Two overlapping spheres (centres r apart): union volume = 2V - lens, lens of two spheres
  // at distance d: pi (2r - d)^2 (d^2 + 4 d r) / (12 d).
  const double d = r;
  const double lens = M_PI * std::pow(2 * r - d, 2) * (d * d + 4 * d * r) / (12 * d);
  MassProperties ov =
      union_mass_properties({{Vec3(-d / 2, 0, 0), r}, {Vec3(d / 2, 0, 0), r}}, rho, 3);
  EXPECT_FALSE(ov.exact);
  EXPECT_TRUE(near_rel(ov.mass, rho * (2 * 4.0 / 3.0 * M_PI * r * r * r - lens), 2e-3));
  EXPECT_TRUE(near_rel(ov.centroid.norm(), 0.0, 1e-12, r));
  // 2D: union area of two disks at distance d: 2 pi r^2 - lens area.
  const double lens2 = 2 * r * r * std::acos(d / (2 * r)) - 0.5 * d * std::sqrt(4 * r * r - d * d);
  MassProperties ov2 =
      union_mass_properties({{Vec3(-d / 2, 0, 0), r}, {Vec3(d / 2, 0, 0), r}}, rho, 2);
  EXPECT_TRUE(near_rel(ov2.mass, rho * (2 * M_PI * r * r - lens2), 2e-3));
}

TEST(Clumps, TorqueFreeClumpConservesAngularMomentumAndEnergy) {
  // An asymmetric clump (three principal moments differ) spinning about a non-principal axis.
  Model m;
  m.settings.dim = 3;
  m.settings.local_damping = 0;
  m.settings.timestep = 1e-5;
  const std::vector<Pebble> p{{Vec3(0, 0, 0), 0.05},
                              {Vec3(0.09, 0, 0), 0.04},
                              {Vec3(0.02, 0.07, 0), 0.03},
                              {Vec3(0.03, 0.02, 0.06), 0.025}};
  m.add_clump(p, 2600, m.group_index("rock"), 1, 1, Vec3(0.1, 0, 0), Vec3(3, -5, 7));
  const Clump& c = m.clumps[0];
  EXPECT_GT(std::abs(c.inertia[0] - c.inertia[1]), 1e-3 * c.inertia[2]);
  EXPECT_GT(std::abs(c.inertia[1] - c.inertia[2]), 1e-3 * c.inertia[2]);
  m.initialize();
  const Vec3 L0 = c.L;
  const Vec3 X0 = c.pos;
  std::vector<double> arm0;
  for (const Pebble& q : p)
    arm0.push_back((q.position - X0).norm());
  const double E0 = m.energy().kinetic();
  EXPECT_GT(E0, 0);
  Vec3 w0 = c.spin;
  m.cycle(100000);                                  // 1 s: about a revolution per 0.7 s
  EXPECT_GT((c.spin - w0).norm(), 0.1 * w0.norm()); // the spin axis precesses (a real test)
  EXPECT_TRUE(near_rel((c.L - L0).norm(), 0.0, 1e-6, L0.norm())) << (c.L - L0).norm();
  EXPECT_TRUE(near_rel(m.energy().kinetic(), E0, 1e-6));
  // The centroid drifts at its constant velocity; the pebbles ride on the body.
  EXPECT_TRUE(near_rel((c.pos - X0 - Vec3(0.1, 0, 0) * m.time()).norm(), 0, 1e-12, 1.0));
  for (std::size_t a = 0; a < c.pebbles.size(); ++a) {
    const std::size_t i = static_cast<std::size_t>(c.pebbles[a]);
    EXPECT_TRUE(near_rel((m.balls.pos[i] - c.pos).norm(), arm0[a], 1e-12));
    EXPECT_TRUE(near_rel((m.balls.vel[i] - c.vel - c.spin.cross(m.balls.pos[i] - c.pos)).norm(), 0,
                         1e-12, c.spin.norm()));
  }
  EXPECT_TRUE(m.contacts().empty()); // pebbles of one clump never touch
}

TEST(Clumps, OnePebbleClumpFallsLikeABall) {
  for (int dim : {2, 3}) {
    auto run = [&](bool as_clump) {
      Model m;
      m.settings.dim = dim;
      m.settings.local_damping = 0.3;
      m.settings.gravity = dim == 2 ? Vec3(0, -9.81, 0) : Vec3(0, 0, -9.81);
      const Vec3 up = dim == 2 ? Vec3::UnitY() : Vec3::UnitZ();
      // a slope, so the body slides and spins as well as bouncing
      m.walls.push_back(test::plane_wall(dim, Vec3::Zero(), (up + 0.4 * Vec3::UnitX()), 2.0));
      add_rule(m, true, linear_props(1e6, 5e5, 0.3));
      const Vec3 x0 = 0.1 * up;
      const Vec3 v0 = Vec3(0.3, 0, 0) - 0.5 * up;
      if (as_clump) {
        m.add_clump({{x0, 0.04}}, 2600, m.group_index("rock"), 1, 1, v0, Vec3::Zero());
      } else {
        const std::size_t b = m.balls.add(dim, 1, x0, 0.04, 2600, m.group_index("rock"));
        m.balls.vel[b] = v0;
      }
      m.initialize();
      m.cycle(20000);
      return std::make_pair(m.balls.pos[0], m.energy());
    };
    const auto [xb, eb] = run(false);
    const auto [xc, ec] = run(true);
    EXPECT_GT(ec.slip, 0) << dim;
    EXPECT_TRUE(near_rel((xc - xb).norm(), 0, 1e-9, xb.norm()))
        << dim << ": " << xb.transpose() << " vs " << xc.transpose();
    EXPECT_TRUE(near_rel(ec.kinetic(), eb.kinetic(), 1e-8, 1e-12)) << dim;
    EXPECT_TRUE(near_rel(ec.local_damping, eb.local_damping, 1e-8)) << dim;
  }
}

TEST(Clumps, GroupEnergiesSumToTheModelInATwoClumpRockfall) {
  // Thesis Fig. 4: a rock of two clumps, parallel-bonded together, falls onto a slope made of
  // wall segments, breaks its bond or not, bounces and slides.
  Model m;
  m.settings.dim = 2;
  m.settings.local_damping = 0;
  m.settings.gravity = Vec3(0, -9.81, 0);
  m.settings.timestep_safety = 0.1; // impacts need small steps for a tight balance
  Wall slope;
  slope.name = "slope";
  const std::vector<Vec3> pts{Vec3(-1, 0.6, 0), Vec3(0, 0, 0), Vec3(1.5, -0.5, 0),
                              Vec3(3, -0.6, 0)};
  for (std::size_t k = 0; k + 1 < pts.size(); ++k) {
    Facet f;
    f.nv = 2;
    f.v[0] = pts[k];
    f.v[1] = pts[k + 1];
    slope.facets.push_back(f);
  }
  m.walls.push_back(slope);
  LinearPBondProps pb;
  pb.linear = linear_props(1e8, 5e7, 0.5);
  pb.pb_kn = 1e9;
  pb.pb_ks = 5e8;
  pb.pb_ten = 1e6;
  pb.pb_coh = 1e6;
  add_rule(m, false, pb);
  PowerPlasticProps pp;
  pp.pp_kn = 1e8;
  pp.pp_ks = 4e7;
  pp.pp_fric = 0.5;
  pp.pp_T = 1e5;
  pp.pp_b = 3;
  add_rule(m, true, pp);
  const double r = 0.04;
  m.add_clump({{Vec3(-0.2, 0.5, 0), r},
               {Vec3(-0.2 + 2 * r, 0.5, 0), r},
               {Vec3(-0.2 + r, 0.5 + 1.7 * r, 0), r}},
              2600, m.group_index("clump1"), 1, 1, Vec3(0.5, 0, 0), Vec3(0, 0, 2));
  m.add_clump({{Vec3(-0.2 + 4 * r, 0.5, 0), r}, {Vec3(-0.2 + 6 * r, 0.5, 0), r}}, 2600,
              m.group_index("clump2"), 2, 4, Vec3(0.5, 0, 0), Vec3(0, 0, 2));
  m.initialize();
  ASSERT_FALSE(m.contacts().empty()); // the bond between the clumps
  const double Einit = m.energy().initial_total;
  double worst_sum = 0, worst_balance = 0, max_body = 0, bond_seen = 0, plastic = 0;
  for (int k = 0; k < 140; ++k) { // 1.5 s: fall, break the bond, bounce and slide
    m.cycle(500);
    const EnergyLedger e = m.energy();
    const std::vector<EnergyLedger> g = m.group_energy();
    EnergyLedger s;
    for (const EnergyLedger& x : g) {
      s.kinetic_translational += x.kinetic_translational;
      s.kinetic_rotational += x.kinetic_rotational;
      s.strain += x.strain;
      s.bond_strain += x.bond_strain;
      s.body_work += x.body_work;
      s.gravity_work += x.gravity_work;
      s.local_damping += x.local_damping;
      s.slip += x.slip;
      s.dashpot += x.dashpot;
      s.plastic += x.plastic;
      s.bond_break += x.bond_break;
    }
    const double scale = e.balance_scale();
    for (auto [a, b] : {std::pair{s.kinetic(), e.kinetic()},
                        {s.strain, e.strain},
                        {s.bond_strain, e.bond_strain},
                        {s.body_work, e.body_work},
                        {s.slip, e.slip},
                        {s.plastic, e.plastic},
                        {s.dashpot, e.dashpot},
                        {s.local_damping, e.local_damping},
                        {s.gravity_work, e.gravity_work},
                        {s.bond_break, e.bond_break}})
      worst_sum = std::max(worst_sum, std::abs(a - b) / scale);
    worst_balance = std::max(worst_balance, std::abs(e.balance_error()) / scale);
    max_body = std::max(max_body, e.body_work);
    bond_seen = std::max(bond_seen, e.bond_strain);
    plastic = e.plastic;
  }
  // both clumps fell, so both groups carry body work
  const std::vector<EnergyLedger> g = m.group_energy();
  EXPECT_GT(g[static_cast<std::size_t>(m.group_index("clump1"))].body_work, 0);
  EXPECT_GT(g[static_cast<std::size_t>(m.group_index("clump2"))].body_work, 0);
  EXPECT_LT(worst_sum, 1e-12);
  EXPECT_LT(worst_balance, 5e-3);
  EXPECT_GT(max_body, 10 * Einit); // the rock fell
  EXPECT_GT(bond_seen, 0);
  EXPECT_GT(m.energy().bond_break, 0); // the bond broke at the impact
  EXPECT_GT(plastic, 0);               // it hit the slope
  EXPECT_GT(m.energy().slip, 0);
}
