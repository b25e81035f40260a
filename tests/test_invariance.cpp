// Rigid-body invariance and the contact-plane frame update (FJ memo Eq. 5).
#include "core/geometry.hpp"
#include "helpers.hpp"

#include <algorithm>
#include <numbers>
#include <random>

using namespace rocklab;
using rocklab::test::near_rel;

namespace {

// A compressed cluster of frictional balls with spins, between two walls, run for a while.
// Everything (positions, velocities, spins, walls, gravity) goes through x -> R x + shift.
struct Snapshot {
  std::vector<double> force_mags, normal_forces, speeds;
  EnergyLedger energy;
};

Snapshot run_cluster(const Eigen::Matrix3d& R, const Vec3& shift) {
  Model m;
  // Local damping acts per global component (-alpha |F_i| sign(v_i)), so it is not rotation
  // invariant by construction; the invariance check uses the dashpots for dissipation instead.
  m.settings.local_damping = 0.0;
  m.settings.timestep = 5e-7;
  m.settings.margin = 5e-4;
  m.settings.gravity = R * Vec3(0, 0, -9.81);
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(-1, 1);
  const double r = 0.005;
  int id = 1;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 3; ++k) {
        const Vec3 x(i * 2 * r + 0.02 * r * u(rng), j * 2 * r + 0.02 * r * u(rng), r + k * 2 * r);
        const std::size_t b = m.balls.add(3, id++, R * x + shift, r * (1 + 0.02 * u(rng)), 2650, 0);
        m.balls.vel[b] = R * Vec3(0.05 * u(rng), 0.05 * u(rng), 0.05 * u(rng));
        m.balls.spin[b] = R * Vec3(5 * u(rng), 5 * u(rng), 5 * u(rng));
      }
  Wall floor = test::plane_wall(3, R * Vec3(0.015, 0.015, 0) + shift, R * Vec3::UnitZ(), 0.2);
  Wall lid =
      test::plane_wall(3, R * Vec3(0.015, 0.015, 0.0301) + shift, R * -Vec3::UnitZ(), 0.2, "lid");
  lid.velocity = R * Vec3(0, 0, -0.2);
  lid.spin = R * Vec3(0, 0, 0.5);
  m.walls = {floor, lid};
  LinearProps p;
  p.kn = 2e4;
  p.ks = 1e4;
  p.fric = 0.4;
  p.dp_nratio = 0.1;
  p.dp_sratio = 0.1;
  m.rules.push_back(test::linear_rule(false, p));
  m.rules.push_back(test::linear_rule(true, p));
  m.initialize();
  m.cycle(1000);
  Snapshot s;
  for (std::size_t ci = 0; ci < m.contacts().size(); ++ci) {
    const ContactOutput& o = m.contact_outputs()[ci];
    s.force_mags.push_back(o.force.norm());
    s.normal_forces.push_back(local_components(m.contacts()[ci], o).Fn);
  }
  for (std::size_t i = 0; i < m.balls.size(); ++i)
    s.speeds.push_back(m.balls.vel[i].norm() + m.balls.spin[i].norm());
  s.energy = m.energy();
  return s;
}

} // namespace

TEST(Invariance, RotatedAndTranslatedSceneGivesSameMagnitudes) {
  const Snapshot a = run_cluster(Eigen::Matrix3d::Identity(), Vec3::Zero());
  const Eigen::Matrix3d R =
      (Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()) * Eigen::AngleAxisd(2.1, Vec3::UnitX()))
          .toRotationMatrix();
  // The shift is of the scene's own size: a far larger one (metres for a 3 cm cluster) costs
  // position resolution (|x| eps per update) and alone perturbs 1e-5 m overlaps at 1e-9.
  const Snapshot b = run_cluster(R, Vec3(0.03, -0.05, 0.02));
  ASSERT_EQ(a.force_mags.size(), b.force_mags.size());
  double fmax = 0;
  for (double f : a.force_mags)
    fmax = std::max(fmax, f);
  ASSERT_GT(fmax, 0.0);
  // Criterion: every contact agrees to 1e-10 of the peak force (max-norm relative), and every
  // contact carrying at least 1 % of the peak agrees to 1e-10 of its own magnitude.
  std::size_t loaded = 0;
  for (std::size_t i = 0; i < a.force_mags.size(); ++i) {
    EXPECT_LE(std::abs(b.force_mags[i] - a.force_mags[i]), 1e-10 * fmax) << "contact " << i;
    EXPECT_LE(std::abs(b.normal_forces[i] - a.normal_forces[i]), 1e-10 * fmax) << "contact " << i;
    if (a.force_mags[i] >= 0.01 * fmax) {
      EXPECT_TRUE(near_rel(b.force_mags[i], a.force_mags[i], 1e-10)) << "contact " << i;
      EXPECT_TRUE(near_rel(b.normal_forces[i], a.normal_forces[i], 1e-10)) << "contact " << i;
      ++loaded;
    }
  }
  EXPECT_GT(loaded, 10u);
  for (std::size_t i = 0; i < a.speeds.size(); ++i)
    EXPECT_TRUE(near_rel(b.speeds[i], a.speeds[i], 1e-10, 1e-3));
  EXPECT_TRUE(near_rel(b.energy.kinetic(), a.energy.kinetic(), 1e-10));
  EXPECT_TRUE(near_rel(b.energy.strain, a.energy.strain, 1e-10));
  EXPECT_TRUE(near_rel(b.energy.slip, a.energy.slip, 1e-10));
  EXPECT_TRUE(near_rel(b.energy.dashpot, a.energy.dashpot, 1e-10));
  EXPECT_TRUE(near_rel(b.energy.boundary_work, a.energy.boundary_work, 1e-10));
  EXPECT_GT(a.energy.slip, 0.0); // the scene does exercise friction
}

TEST(ContactFrame, StaysOrthonormalUnderRandomMotion) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  Vec3 n = Vec3(1, 0.3, -0.2).normalized();
  Vec3 s = initial_s_axis(n), t = n.cross(s);
  double worst = 0;
  for (int k = 0; k < 100000; ++k) {
    const Vec3 n_new = (n + 0.01 * Vec3(u(rng), u(rng), u(rng))).normalized();
    const Vec3 w1(50 * u(rng), 50 * u(rng), 50 * u(rng)), w2(50 * u(rng), 50 * u(rng), 50 * u(rng));
    update_plane_axes(3, n, n_new, w1, w2, 1e-4, s, t);
    n = n_new;
    worst = std::max({worst, std::abs(s.norm() - 1), std::abs(t.norm() - 1), std::abs(s.dot(t)),
                      std::abs(s.dot(n)), std::abs(t.dot(n)), (s.cross(t) - n).norm()});
  }
  EXPECT_LT(worst, 1e-12);
}

TEST(ContactFrame, FollowsSpinAboutTheNormal) {
  // Both pieces spin about the fixed normal at w: s turns rigidly by w dt per step (Eq. 5).
  const Vec3 n = Vec3(0.2, -0.5, 0.8).normalized();
  Vec3 s = initial_s_axis(n), t = n.cross(s);
  const Vec3 s0 = s, t0 = t;
  const double w = 3.0, dt = 1e-4;
  const int steps = 5000;
  for (int k = 0; k < steps; ++k)
    update_plane_axes(3, n, n, w * n, w * n, dt, s, t);
  const double angle = std::atan2(s.dot(t0), s.dot(s0));
  EXPECT_TRUE(near_rel(angle, w * dt * steps, 1e-10));
}

TEST(ContactFrame, TwoDimensionalConvention) {
  Vec3 s, t;
  const Vec3 n = Vec3(0.6, 0.8, 0);
  update_plane_axes(2, n, n, Vec3::Zero(), Vec3::Zero(), 1e-3, s, t);
  EXPECT_EQ(s, -Vec3::UnitZ());
  EXPECT_TRUE(near_rel((Vec3::UnitZ().cross(n) - t).norm() + 1, 1.0, 1e-15));
  EXPECT_NEAR(s.cross(t).dot(n), 1.0, 1e-15); // n = s x t
}

TEST(ContactFrame, RelativeIncrementsOfARigidPairVanish) {
  // Two balls moving and spinning together as one rigid body: no relative motion (Eq. 7-11).
  const Vec3 x1(0, 0, 0), x2(0.02, 0.01, -0.005);
  const Vec3 v(1, -2, 0.5), w(3, 4, -5);
  const PlaneGeometry g = ball_ball_plane(x1, 0.011, x2, 0.012);
  const Vec3 s = initial_s_axis(g.n), t = g.n.cross(s);
  ContactKinematics k;
  // The velocity of the body at x2 follows from the rigid motion about x1.
  relative_increments(g.xc, g.n, s, t, x1, v, w, x2, v + w.cross(x2 - x1), w, 1e-3, k);
  for (double d : {k.d_dn, k.d_dss, k.d_dst, k.d_tt, k.d_tbs, k.d_tbt})
    EXPECT_NEAR(d, 0.0, 1e-15);
}
