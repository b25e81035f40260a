// Flat-joint memo section 2.2 (interlocked grain) and the exact 3D element integrals.
#include "contact/flat_joint.hpp"
#include "helpers.hpp"

#include <numbers>
#include <random>

using namespace rocklab;
using rocklab::test::near_rel;

namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kKn = 29e9 / 12.5e-3, kRfj = 5e-3, kTheta = 0.01;

struct Interlocked {
  std::vector<std::vector<double>> element_fn; // per contact, after stage 1
  double centre_moment_z = 0;                  // contact moment on the central grain
  std::vector<double> outer_rotation;          // integrated spin about z in stage 2
  double force_after = 0, force_before = 0;    // largest element |Fn| after each stage
};

Interlocked run(const std::string& name, const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity()) {
  Scene s = load_scene(test::source_dir() + "/examples/verification/" + name + ".json");
  test::transform_model(*s.model, R, Vec3::Zero());
  Model& m = *s.model;
  m.initialize();
  auto apply = [&](const Stage& st) {
    for (const BallChange& bc : st.set) {
      if (bc.spin)
        m.balls.spin[bc.index] = R * *bc.spin;
      m.balls.fixity[bc.index] =
          static_cast<std::uint8_t>((m.balls.fixity[bc.index] | bc.fix) & ~bc.free);
    }
  };
  auto max_fn = [&]() {
    double f = 0;
    for (const auto& fj : m.batches().of<FlatJoint>().contacts)
      for (const auto& e : m.batches().of<FlatJoint>().pool.of(fj))
        f = std::max(f, std::abs(e.Fn));
    return f;
  };
  Interlocked out;
  apply(s.stages[0]);
  m.cycle(s.stages[0].run.cycles);
  for (const auto& fj : m.batches().of<FlatJoint>().contacts) {
    std::vector<double> fn;
    for (const auto& e : m.batches().of<FlatJoint>().pool.of(fj))
      fn.push_back(e.Fn);
    out.element_fn.push_back(fn);
  }
  out.centre_moment_z = (R.transpose() * m.balls.moment[0]).z();
  out.force_before = max_fn();
  apply(s.stages[1]);
  out.outer_rotation.assign(4, 0.0);
  for (std::int64_t k = 0; k < s.stages[1].run.cycles; ++k) {
    m.cycle(1);
    for (int b = 0; b < 4; ++b)
      out.outer_rotation[b] += (R.transpose() * m.balls.spin[b + 1]).z() * m.timestep();
  }
  out.force_after = max_fn();
  return out;
}
} // namespace

TEST(InterlockedGrain, TwoDimensional) {
  const Interlocked r = run("interlocked_2d");
  ASSERT_EQ(r.element_fn.size(), 4u);
  for (const auto& fn : r.element_fn) {
    // Half of each face is pressed; the largest compression sits at the far end (element 1 or 4).
    int compressed = 0;
    for (double f : fn)
      compressed += f < 0;
    EXPECT_EQ(compressed, 2);
    const double end = std::min(fn.front(), fn.back());
    for (double f : fn)
      EXPECT_GE(f, end);
    EXPECT_LT(end, 0.0);
  }
  // The contact moments resist the imposed rotation: exactly 4 kn theta R^3 / 3 (half faces).
  EXPECT_TRUE(near_rel(r.centre_moment_z, -4 * kKn * kTheta * std::pow(kRfj, 3) / 3, 1e-9));
  // After release the outer grains turn the same way as the centre and relieve the joints.
  for (double rot : r.outer_rotation)
    EXPECT_TRUE(near_rel(rot, kTheta, 1e-3));
  EXPECT_LT(r.force_after, 1e-6 * r.force_before);
}

TEST(InterlockedGrain, ThreeDimensional) {
  for (const char* name : {"interlocked_3d", "interlocked_3d_exact"}) {
    const Interlocked r = run(name);
    ASSERT_EQ(r.element_fn.size(), 4u);
    for (const auto& fn : r.element_fn) {
      // Half of the 16 elements are pressed (the zero-gap line runs along sector edges, so the
      // exact integrals leave round-off slivers on the other half: ignore those).
      const double peak = -*std::min_element(fn.begin(), fn.end());
      int compressed = 0;
      for (double f : fn)
        compressed += f < -1e-9 * peak;
      EXPECT_EQ(compressed, 8) << name;
    }
    EXPECT_LT(r.centre_moment_z, 0.0) << name;
    for (double rot : r.outer_rotation)
      EXPECT_TRUE(near_rel(rot, kTheta, 1e-3)) << name;
    EXPECT_LT(r.force_after, 1e-6 * r.force_before) << name;
  }
  // The exact option reproduces the half-disk closed form 4 kn theta pi R^4 / 8.
  const Interlocked e = run("interlocked_3d_exact");
  EXPECT_TRUE(near_rel(e.centre_moment_z, -4 * kKn * kTheta * kPi * std::pow(kRfj, 4) / 8, 1e-9));
  // Rotated arbitrarily: the same moment and rotations.
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.9, Vec3(1, -2, 0.5).normalized()).toRotationMatrix();
  const Interlocked f = run("interlocked_3d_exact", R);
  EXPECT_TRUE(near_rel(f.centre_moment_z, e.centre_moment_z, 1e-9));
  for (int b = 0; b < 4; ++b)
    EXPECT_TRUE(near_rel(f.outer_rotation[b], e.outer_rotation[b], 1e-6));
}

TEST(FlatJointExact, ClippedSectorMomentsMatchQuadrature) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 200; ++trial) {
    const double r1 = trial % 3 == 0 ? 0.0 : 0.3 + 0.2 * u(rng), r2 = 1.0;
    const double a1 = kPi * (1 + u(rng)), a2 = a1 + 2 * kPi / (3 + trial % 6);
    const double gs = 0.5 * u(rng), bs = u(rng), bt = u(rng);
    const flatjoint::Moments m = flatjoint::clipped_moments(r1, r2, a1, a2, gs, bs, bt);
    // Midpoint quadrature in polar coordinates.
    const int n = 600;
    flatjoint::Moments q{};
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const double r = r1 + (r2 - r1) * (i + 0.5) / n, a = a1 + (a2 - a1) * (j + 0.5) / n;
        const double s = r * std::cos(a), t = r * std::sin(a);
        if (gs + bs * s + bt * t >= 0)
          continue;
        const double w = r * (r2 - r1) / n * (a2 - a1) / n;
        const double f[6] = {1, s, t, s * s, s * t, t * t};
        for (int k = 0; k < 6; ++k)
          q[k] += w * f[k];
      }
    for (int k = 0; k < 6; ++k)
      EXPECT_NEAR(m[k], q[k], 4e-3 * (a2 - a1)) << "trial " << trial << " moment " << k;
  }
}

TEST(FlatJointExact, FullSectorMatchesTheBondedSecondMoments) {
  const FlatJointGeometry& g = flat_joint_geometry(3, 3, 16);
  for (std::size_t i = 0; i < g.A.size(); ++i) {
    const flatjoint::Moments m =
        flatjoint::clipped_moments(g.r1[i], g.r2[i], g.a1[i], g.a2[i], -1.0, 0.0, 0.0);
    EXPECT_TRUE(near_rel(m[0], g.A[i], 1e-12));
    EXPECT_TRUE(near_rel(m[1], g.s[i] * g.A[i], 1e-12, 1e-3));
    EXPECT_TRUE(near_rel(m[2], g.t[i] * g.A[i], 1e-12, 1e-3));
    EXPECT_TRUE(near_rel(m[3], g.Ixx[i], 1e-12, 1e-3));
    EXPECT_TRUE(near_rel(m[4], g.Ixy[i], 1e-12, 1e-3));
    EXPECT_TRUE(near_rel(m[5], g.Iyy[i], 1e-12, 1e-3));
  }
}
