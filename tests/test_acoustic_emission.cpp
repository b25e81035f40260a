// Acoustic emission with known answers: the reading of moment tensors (scalar moment, Mw, source
// shares, Feignier & Young's R, P and T axes), the b-value estimator on synthetic Gutenberg-Richter
// samples, and the monitor on hand-built bonded grains: a bond broken in pure tension is a tensile
// source with its T axis along the bond, a bond broken in pure shear a double couple with P and T
// at 45 degrees to the slip plane.
#include "helpers.hpp"
#include "lab/ae_monitor.hpp"
#include "lab/b_value.hpp"
#include "lab/moment_tensor.hpp"

#include "contact/contact_bond.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <numbers>
#include <random>

namespace rocklab {
namespace {

TEST(MomentTensor, ADoubleCoupleOfKnownMomentReadsItsMomentMagnitude) {
  const double m0 = 1e3; // N m: Mw = 2/3 x 3 - 6 = -4
  Mat3 m = Mat3::Zero();
  m(0, 0) = m0, m(2, 2) = -m0;
  const SourceReading r = read_source(m, 3);
  EXPECT_NEAR(r.m0, m0, 1e-9);
  EXPECT_NEAR(r.mw, -4.0, 1e-12);
  EXPECT_NEAR(moment_magnitude(3.5e6), 2.0 / 3.0 * std::log10(3.5e6) - 6.0, 1e-12);
  EXPECT_TRUE(std::isnan(moment_magnitude(0)));
  EXPECT_NEAR(r.isotropic, 0, 1e-12);
  EXPECT_NEAR(r.clvd, 0, 1e-12);
  EXPECT_NEAR(r.double_couple, 1, 1e-12);
  EXPECT_NEAR(r.r, 0, 1e-12);
  EXPECT_EQ(r.type, SourceClass::Shear);
  EXPECT_NEAR(std::abs(r.t_axis.x()), 1, 1e-12);
  EXPECT_NEAR(std::abs(r.p_axis.z()), 1, 1e-12);
}

TEST(MomentTensor, AnOpeningCrackIsTensileAClosingOneImplosiveWhateverTheFrame) {
  // A crack opening along its normal in a Poisson-free source: M = diag(2, 0, 0).
  Mat3 m = Mat3::Zero();
  m(0, 0) = 2;
  const SourceReading t = read_source(m, 3);
  EXPECT_NEAR(t.isotropic, 1.0 / 3.0, 1e-12); // tr/3 against the deviatoric 4/3
  EXPECT_NEAR(t.clvd, 2.0 / 3.0, 1e-12);      // eps = 1/2
  EXPECT_NEAR(t.double_couple, 0, 1e-12);
  EXPECT_NEAR(t.r, 100 * 2 / (2 + 8.0 / 3.0), 1e-9); // 42.9 > 30
  EXPECT_EQ(t.type, SourceClass::Tensile);
  EXPECT_EQ(read_source(-m, 3).type, SourceClass::Implosive);
  EXPECT_NEAR(read_source(-m, 3).isotropic, -1.0 / 3.0, 1e-12);
  // Rotated: the same shares and moment, the T axis along the rotated normal.
  const Mat3 q = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const SourceReading rot = read_source(q * m * q.transpose(), 3);
  EXPECT_NEAR(rot.m0, t.m0, 1e-12);
  EXPECT_NEAR(rot.isotropic, t.isotropic, 1e-12);
  EXPECT_NEAR(rot.clvd, t.clvd, 1e-12);
  EXPECT_NEAR(std::abs(rot.t_axis.dot(q.col(0))), 1, 1e-12);
  // 2D: the in-plane block; its deviatoric part is a double couple.
  Mat3 p = Mat3::Zero();
  p(0, 0) = 2;
  const SourceReading two = read_source(p, 2);
  EXPECT_NEAR(two.isotropic, 0.5, 1e-12);
  EXPECT_NEAR(two.double_couple, 0.5, 1e-12);
  EXPECT_NEAR(two.r, 50, 1e-9);
  EXPECT_EQ(two.type, SourceClass::Tensile);
}

// magnitudes >= mc from a Gutenberg-Richter law with slope b (exponential in M), and `below`
// more spread evenly over the half unit below mc (an incomplete catalogue there).
std::vector<double> gutenberg_richter(double b, double mc, int n, int below, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::exponential_distribution<double> excess(b * std::log(10.0));
  std::uniform_real_distribution<double> low(mc - 0.5, mc);
  std::vector<double> m;
  for (int i = 0; i < n; ++i)
    m.push_back(mc + excess(rng));
  for (int i = 0; i < below; ++i)
    m.push_back(low(rng));
  return m;
}

TEST(BValue, TheMaximumLikelihoodBOfASyntheticSampleIsWithinItsError) {
  for (const double b : {0.8, 1.0, 1.5}) {
    const BValue est = b_value(gutenberg_richter(b, -4.0, 2000, 300, 7));
    EXPECT_NEAR(est.completeness, -4.0, 1e-9) << b; // the busiest bin is the first complete one
    EXPECT_GE(est.events, 2000);
    EXPECT_NEAR(est.b, b, 2.5 * est.standard_error) << b;
    EXPECT_TRUE(test::near_rel(est.standard_error, b / std::sqrt(2000.0), 0.15)) << b;
  }
  // Too few events above Mc: no b-value.
  EXPECT_TRUE(std::isnan(b_value(gutenberg_richter(1.0, -4.0, 30, 0, 1)).b));
  EXPECT_TRUE(std::isnan(b_value({}).b));
}

// Grains of radius R along a line (3D), bonded by contact bonds: the bond between grains of group
// "source" with the given strengths [N], every other bond far stronger. Local damping 0.7.
struct Bonded {
  std::unique_ptr<Model> m;
  CrackMonitor cracks;
  AeMonitor ae;
  std::vector<Event> events;
  void run(int steps) {
    for (int i = 0; i < steps; ++i) {
      m->cycle(1);
      events.clear();
      m->drain_events(events);
      cracks.consume(*m, events);
      ae.step(*m, cracks.cracks(), 1e-8);
    }
  }
};

constexpr double kR = 1e-3;

Bonded bonded(const std::vector<Vec3>& at, const std::vector<bool>& source, double tenf,
              double shearf) {
  Bonded b;
  b.m = std::make_unique<Model>();
  Model& m = *b.m;
  m.settings.gravity = Vec3::Zero();
  const int rock = m.group_index("rock"), src = m.group_index("source");
  for (std::size_t i = 0; i < at.size(); ++i)
    m.balls.add(3, static_cast<std::int64_t>(i + 1), at[i], kR, 2600, source[i] ? src : rock);
  ContactBondProps weak;
  weak.linear.kn = weak.linear.ks = 1e6; // N/m
  weak.cb_tenf = tenf, weak.cb_shearf = shearf;
  weak.bond_gap_hi = 1e-6;
  ContactBondProps strong = weak;
  strong.cb_tenf = strong.cb_shearf = 1e4;
  ModelRule w;
  w.group1 = w.group2 = src;
  w.props = weak;
  ModelRule s;
  s.props = strong;
  m.rules = {w, s};
  return b;
}

TEST(AeMonitor, ABondBrokenInPureTensionIsATensileSourceAlongTheBond) {
  // 0 - 1 = 2 - 3 along x; 0 held, 3 pulled: the weak bond 1-2 (tension strength 1 N) breaks.
  const double d = 2 * kR - 1e-8;
  Bonded b = bonded({{0, 0, 0}, {d, 0, 0}, {2 * d, 0, 0}, {3 * d, 0, 0}},
                    {false, true, true, false}, 1.0, 1e3);
  Model& m = *b.m;
  m.balls.fixity[0] = m.balls.fixity[3] = 0x3f;
  m.balls.vel[3] = Vec3(1e-3, 0, 0); // m/s
  m.initialize();
  b.ae.set_duration(400 * m.timestep());
  b.run(6000);
  b.ae.finish(m.time());
  ASSERT_EQ(b.cracks.cracks().size(), 1u);
  EXPECT_EQ(b.cracks.cracks()[0].mode, 1);
  ASSERT_EQ(b.ae.event_of_crack(), std::vector<int>{0});
  const auto src = b.ae.sources();
  ASSERT_EQ(src.size(), 1u);
  EXPECT_EQ(src[0].grains, 2);
  const SourceReading r = read_source(src[0].tensor, 3);
  EXPECT_EQ(r.type, SourceClass::Tensile);
  EXPECT_GT(r.isotropic, 0.3);
  EXPECT_NEAR(r.r, 100 * 2 / (2 + 8.0 / 3.0), 1.0); // a uniaxial opening
  EXPECT_NEAR(std::abs(r.t_axis.x()), 1, 1e-6);
  // Two outer contacts each lose about the bond's 1 N at 2R from the crack: M_xx ~ 4 R x 1 N
  // (up to twice that while the released grains overshoot).
  EXPECT_GT(src[0].tensor(0, 0), 0.9 * 4 * kR * 1.0);
  EXPECT_LT(src[0].tensor(0, 0), 2.1 * 4 * kR * 1.0);
}

TEST(AeMonitor, ABondBrokenInPureShearIsADoubleCoupleWithItsAxesAt45Degrees) {
  // A column along y: loader 0, source grains 1 and 2 bonded across the plane y = 0, loader 3.
  // The loaders move apart along x, so every bond carries the same shear until the weak one, 1-2
  // (shear strength 1 N), breaks. The source grains cannot rotate (the loaders' couple on them
  // is not balanced by contacts).
  const double d = 2 * kR - 1e-8;
  Bonded b = bonded({{0, 1.5 * d, 0}, {0, 0.5 * d, 0}, {0, -0.5 * d, 0}, {0, -1.5 * d, 0}},
                    {false, true, true, false}, 1e3, 1.0);
  Model& m = *b.m;
  m.balls.fixity[0] = m.balls.fixity[3] = 0x3f;
  const auto no_spin = static_cast<std::uint8_t>(dof_bit(kRx) | dof_bit(kRy) | dof_bit(kRz));
  m.balls.fixity[1] = m.balls.fixity[2] = no_spin;
  m.balls.vel[0] = Vec3(1e-3, 0, 0), m.balls.vel[3] = Vec3(-1e-3, 0, 0);
  m.initialize();
  b.ae.set_duration(400 * m.timestep());
  b.run(6000);
  b.ae.finish(m.time());
  ASSERT_GE(b.cracks.cracks().size(), 1u);
  EXPECT_EQ(b.cracks.cracks()[0].mode, 2);
  const auto src = b.ae.sources();
  ASSERT_EQ(src.size(), 1u);
  const SourceReading r = read_source(src[0].tensor, 3);
  EXPECT_EQ(r.type, SourceClass::Shear);
  EXPECT_LT(std::abs(r.isotropic), 0.05);
  EXPECT_GT(r.double_couple, 0.9);
  const double s = 1 / std::sqrt(2.0);
  EXPECT_NEAR(std::abs(r.t_axis.x()), s, 0.02);
  EXPECT_NEAR(std::abs(r.t_axis.y()), s, 0.02);
  EXPECT_NEAR(std::abs(r.p_axis.x()), s, 0.02);
  EXPECT_NEAR(std::abs(r.t_axis.dot(r.p_axis)), 0, 1e-9);
}

TEST(AeMonitor, CracksAtTouchingGrainsShareAnEventFarOnesDoNot) {
  // Three identical chains pulled alike, so their weak bonds break in the same step: chains A
  // (y = 0) and B (y = d) touch grain by grain, chain C lies far away (y = 10 d).
  const double d = 2 * kR - 1e-8;
  std::vector<Vec3> at;
  std::vector<bool> source;
  for (const double y : {0.0, d, 10 * d})
    for (int i = 0; i < 4; ++i) {
      at.emplace_back(i * d, y, 0);
      source.push_back(i == 1 || i == 2);
    }
  Bonded b = bonded(at, source, 1.0, 1e3);
  Model& m = *b.m;
  for (const std::size_t k : {0, 4, 8})
    m.balls.fixity[k] = m.balls.fixity[k + 3] = 0x3f, m.balls.vel[k + 3] = Vec3(1e-3, 0, 0);
  m.initialize();
  b.ae.set_duration(400 * m.timestep());
  b.run(6000);
  const auto& cs = b.cracks.cracks();
  ASSERT_EQ(cs.size(), 3u);
  std::map<char, int> event; // chain -> event of its crack
  for (std::size_t i = 0; i < cs.size(); ++i)
    event["ABC"[(cs[i].ball1 - 1) / 4]] = b.ae.event_of_crack()[i];
  EXPECT_EQ(event['A'], event['B']);
  EXPECT_NE(event['A'], event['C']);
  b.ae.finish(m.time());
  const auto src = b.ae.sources();
  ASSERT_EQ(src.size(), 2u);
  const AeSource& two = src[static_cast<std::size_t>(event['A'])];
  const AeSource& one = src[static_cast<std::size_t>(event['C'])];
  EXPECT_EQ(two.grains, 4);
  EXPECT_EQ(one.grains, 2);
  // Both tensile along x; the double one has about twice the moment.
  EXPECT_EQ(read_source(two.tensor, 3).type, SourceClass::Tensile);
  EXPECT_EQ(read_source(one.tensor, 3).type, SourceClass::Tensile);
  EXPECT_TRUE(test::near_rel(two.m0, 2 * one.m0, 0.15));
}

} // namespace
} // namespace rocklab
