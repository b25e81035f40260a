// The Brazilian disk's validity (ISRM): where its fracture started, from its crack records
// (lab/protocols/brazilian_validity.cpp), on a disk split from the centre and on disks that failed
// at a platen.
#include "lab/frame/frame_test.hpp"
#include "lab/protocol_table.hpp"
#include "lab/protocols/brazilian.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

using namespace rocklab;

namespace {

// A 3D disk of D = 26 mm, 12 mm thick, loaded along y (the split band: |x| <= 5.2 mm).
SpecimenGeometry disk() {
  SpecimenGeometry g;
  g.dim = 3, g.diametral = true;
  g.center = Vec3(0.05, 0.04, 0.006);
  g.width0 = Vec3(0.026, 0.026, 0);
  g.thickness = 0.012;
  return g;
}

void add(std::vector<Crack>& cracks, const SpecimenGeometry& g, std::int64_t step, double x,
         double y) {
  Crack c;
  c.step = step, c.mode = 1, c.position = g.center + Vec3(x, y, 0.001);
  cracks.push_back(c);
}

} // namespace

TEST(BrazilianValidity, ADiskSplitFromItsCentreIsValid) {
  const SpecimenGeometry g = disk();
  std::vector<Crack> cracks;
  // Cracks start at the centre and run out towards both platens, with some scatter off the band
  // (ignored) and one early crack at a platen.
  add(cracks, g, 90, 0.0005, 0.0125);
  std::int64_t step = 100;
  for (int k = 0; k <= 12; ++k) {
    const double y = 0.001 * k;
    add(cracks, g, step++, 0.0004, y);
    add(cracks, g, step++, -0.0003, -y);
    add(cracks, g, step++, 0.009, 0.3 * y); // outside the band
  }
  const SplitOrigin o = split_origin(cracks, g, step);
  EXPECT_EQ(o.site, "centre");
  EXPECT_TRUE(o.valid);
  EXPECT_LT(o.start, 1.0 / 3.0);
  EXPECT_EQ(o.cracks, 27);                        // 1 + 2 x 13 in the band
  EXPECT_NEAR(o.platen_share, 9.0 / 27.0, 1e-12); // |y| > 8.67 mm: 9 of them, the early one too
  // Only the cracks up to the strength's step count: at step 105 the fracture was at the centre.
  const SplitOrigin early = split_origin(cracks, g, 105);
  EXPECT_EQ(early.cracks, 5);
  EXPECT_TRUE(early.valid);
}

TEST(BrazilianValidity, ADiskCrushedAtAPlatenIsNotValid) {
  const SpecimenGeometry g = disk();
  std::vector<Crack> cracks;
  // Crushing under the top platen first, then a fracture down the diameter from there.
  std::int64_t step = 100;
  for (int k = 0; k < 12; ++k)
    add(cracks, g, step++, 0.0008 * (k % 5 - 2), 0.0128 - 0.0001 * k);
  for (int k = 0; k < 12; ++k)
    add(cracks, g, step++, 0.0002, 0.011 - 0.002 * k);
  const SplitOrigin o = split_origin(cracks, g, step);
  EXPECT_EQ(o.site, "platen");
  EXPECT_FALSE(o.valid);
  EXPECT_GT(o.start, 0.9);
  // Its first cracks at the centre would not save a disk whose damage lies mostly at the
  // platens: both platens crushed, a few cracks in between.
  std::vector<Crack> crushed;
  for (int k = 0; k < 5; ++k)
    add(crushed, g, k, 0, 0.0005 * (k - 2));
  for (int k = 0; k < 24; ++k)
    add(crushed, g, 10 + k, 0.001, (k % 2 ? 1 : -1) * (0.0125 - 0.0002 * (k / 2)));
  const SplitOrigin c = split_origin(crushed, g, 100);
  EXPECT_LT(c.start, 1.0 / 3.0);
  EXPECT_NEAR(c.platen_share, 24.0 / 29.0, 1e-12);
  EXPECT_EQ(c.site, "platen");
  EXPECT_FALSE(c.valid);
}

TEST(BrazilianValidity, ScatteredDamageAlongTheDiameterIsValidAndNoCracksIsNone) {
  // Cracks drawn uniformly along the loaded diameter (a wide strength distribution): a third
  // near the platens, the start about half-way: "diameter", valid.
  const SpecimenGeometry g = disk();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> along(-0.013, 0.013), across(-0.005, 0.005);
  std::vector<Crack> cracks;
  for (int k = 0; k < 400; ++k)
    add(cracks, g, k, across(rng), along(rng));
  const SplitOrigin o = split_origin(cracks, g, 1000);
  EXPECT_NEAR(o.platen_share, 1.0 / 3.0, 0.06);
  EXPECT_EQ(o.site, "diameter");
  EXPECT_TRUE(o.valid);
  const SplitOrigin none = split_origin({}, g, 1000);
  EXPECT_EQ(none.site, "none");
  EXPECT_FALSE(none.valid);
}

// A uniform tension along the loaded diameter scatters its cracks evenly, a third of them within
// D/6 of a platen. With a few dozen diametral cracks (a 2D disk) the median of the first quarter
// then lies in an outer third of 32 % of disks by chance alone (at least 3 of 6): a rule on the
// median only calls every third evenly cracked disk "started at a platen". Counted only beyond
// chance (binomial tail at most 0.05), at most about one in twenty is.
TEST(BrazilianValidity, AnEvenScatterOfAFewCracksIsNotReadAsAPlatenStart) {
  EXPECT_NEAR(binomial_upper_tail(4, 7, 1.0 / 3.0), 379.0 / 2187.0, 1e-12); // 0.1733
  EXPECT_NEAR(binomial_upper_tail(6, 6, 1.0 / 3.0), 1.0 / 729.0, 1e-15);
  EXPECT_DOUBLE_EQ(binomial_upper_tail(0, 6, 1.0 / 3.0), 1.0);
  EXPECT_DOUBLE_EQ(binomial_upper_tail(7, 6, 1.0 / 3.0), 0.0);
  EXPECT_NEAR(binomial_upper_tail(200, 400, 1.0 / 3.0), 0.0, 1e-10); // no overflow at 400
  const SpecimenGeometry g = disk();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> along(-0.013, 0.013), across(-0.005, 0.005);
  const int draws = 4000;
  int median_outer = 0, invalid = 0;
  for (int d = 0; d < draws; ++d) {
    std::vector<Crack> cracks;
    for (int k = 0; k < 24; ++k)
      add(cracks, g, k, across(rng), along(rng));
    const SplitOrigin o = split_origin(cracks, g, 1000);
    ASSERT_EQ(o.first, 6);
    median_outer += o.start > 2.0 / 3.0;
    invalid += !o.valid;
  }
  EXPECT_NEAR(median_outer / double(draws), 0.320, 0.03); // 1 - P(at most 2 of 6)
  EXPECT_LT(invalid / double(draws), 0.06);
  // Five of the first six at a platen is not chance (1.8 %): that disk started there.
  std::vector<Crack> cracks;
  for (int k = 0; k < 5; ++k)
    add(cracks, g, k, 0.0005, 0.0122 - 0.0002 * k);
  for (int k = 0; k < 19; ++k)
    add(cracks, g, 10 + k, 0.0005, 0.0125 - 0.0013 * k);
  const SplitOrigin o = split_origin(cracks, g, 1000);
  EXPECT_EQ(o.first_at_platen, 6); // the run down the diameter begins under the platen too
  EXPECT_LT(o.start_chance, kPlatenChance);
  EXPECT_EQ(o.site, "platen");
  EXPECT_FALSE(o.valid);
}

TEST(BrazilianValidity, ASuiteAveragesItsValidDisksAndCountsThemAll) {
  const std::unique_ptr<FrameTest> bz = make_frame_test("brazilian");
  auto disk = [](double strength, bool valid) {
    return nlohmann::json{{"tensile_strength_Pa", strength},
                          {"fracture_origin", {{"valid", valid}}}};
  };
  SuiteValues v;
  bz->add_to_suite(disk(5e6, false), v); // crushed at a platen: no BTS, its reading said apart
  EXPECT_TRUE(std::isnan(v.get("bts_Pa")));
  EXPECT_DOUBLE_EQ(v.get("bts_not_valid_Pa"), 5e6);
  EXPECT_DOUBLE_EQ(v.get("brazilian_valid"), 0);
  nlohmann::json props;
  bz->suite_results(v, props);
  EXPECT_TRUE(props["bts_Pa"].is_null()); // summary.json: not measured
  bz->add_to_suite(disk(10e6, true), v);
  bz->add_to_suite(disk(12e6, true), v);
  bz->add_to_suite(disk(30e6, false), v);
  EXPECT_DOUBLE_EQ(v.get("bts_Pa"), 11e6); // the valid disks' mean
  EXPECT_DOUBLE_EQ(v.get("bts_not_valid_Pa"), 17.5e6);
  EXPECT_DOUBLE_EQ(v.get("brazilian_valid"), 0.5);
  EXPECT_DOUBLE_EQ(v.get("brazilian_disks"), 4);
}

// A flattened disk's centre tension per 2F/(pi D t): the closed form (sin 2a - a)/a against the
// superposition it comes from. A diametral pair of point loads P at angle phi from the y axis
// gives the centre 2P/(pi D t) of tension normal to its diameter and 6P/(pi D t) of compression
// along it; a load spread evenly over the arcs -a..a sums those pairs.
TEST(FlattenedDisk, TheCentreTensionFactorIsTheSumOfDiametralPointLoads) {
  EXPECT_DOUBLE_EQ(flat_disk_factor(0), 1.0);
  for (double deg : {5.0, 20.0, 30.0, 60.0}) {
    const double a = 0.5 * deg * std::numbers::pi / 180;
    const int n = 2000; // Simpson over phi in [-a, a] of sigma_xx per 2P/(pi D t) per unit load
    double sum = 0;
    for (int i = 0; i <= n; ++i) {
      const double phi = -a + 2 * a * i / n;
      const double w = i == 0 || i == n ? 1 : (i % 2 ? 4 : 2);
      sum += w * (std::cos(phi) * std::cos(phi) - 3 * std::sin(phi) * std::sin(phi));
    }
    const double superposed = sum * (2 * a / n) / 3 / (2 * a);
    EXPECT_NEAR(flat_disk_factor(deg * std::numbers::pi / 180), superposed, 1e-9) << deg;
  }
  EXPECT_NEAR(flat_disk_factor(20 * std::numbers::pi / 180), 0.9596, 1e-4);
}

// The loaded arc (lab/protocols/brazilian_readings.cpp): one contact spreads nothing; a pressure
// spread evenly over [-a, a] (many equal contacts) reads its own half-width a, wherever its centre
// lies; two equal contacts at +-b read the uniform load of the same spread, sqrt(3) b. The
// strength factor at the half-angle asin(a / R) is Hondros' (sin 2a - a) / a.
TEST(BrazilianReadings, TheLoadedArcIsTheUniformLoadWithTheSameSpread) {
  ArcSums one;
  one.add(0.3e-3, 50.0);
  EXPECT_EQ(one.half_width(), 0.0);
  ArcSums even;
  const double a = 2e-3, shift = 0.4e-3;
  const int n = 2001;
  for (int i = 0; i < n; ++i)
    even.add(shift + a * (-1 + 2.0 * (i + 0.5) / n), 3.0);
  EXPECT_NEAR(even.half_width(), a, 1e-6 * a);
  ArcSums pair;
  pair.add(-1e-3, 7.0);
  pair.add(1e-3, 7.0);
  EXPECT_NEAR(pair.half_width(), std::sqrt(3.0) * 1e-3, 1e-15);
  ArcSums none;
  EXPECT_EQ(none.half_width(), 0.0);
  // A 26 mm disk loaded over 2a = 40 deg: its centre's tension is 0.84 of the line load's.
  EXPECT_NEAR(flat_disk_factor(40 * std::numbers::pi / 180), 0.8415, 1e-3);
}

// The stop rule's watch, fed one reading at a time, finds the same loss as the whole record read
// at the end, and reports it only once it has lasted `persist` steps.
TEST(BrazilianReadings, TheTensionWatchFindsTheLossAsTheRecordDoes) {
  std::vector<TensionReading> r;
  for (int k = 0; k <= 600; ++k) { // climbing at 0.6, a loss to 0.3 from step 3000 on
    const double load = 1e6 + 1e4 * std::min(k, 400);
    r.push_back({10 * k, load, k < 300 ? 0.6 : 0.3});
  }
  TensionWatch w(0.6, 0.3, 2e6, 1000);
  std::int64_t seen = -1;
  for (const TensionReading& x : r) {
    w.add(x);
    if (seen < 0 && w.lost().step >= 0)
      seen = x.step;
  }
  const TensionLoss whole = tension_loss(r, 0.6, 0.3, 2e6, 1000);
  EXPECT_EQ(whole.step, 3000);
  EXPECT_EQ(w.result().step, whole.step);
  EXPECT_DOUBLE_EQ(w.result().reference, whole.reference);
  EXPECT_EQ(seen, 4000); // known once it lasted 1000 steps
}
