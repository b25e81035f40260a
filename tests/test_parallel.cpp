// The cycle's thread plan and spatial renumbering (issue 40): results never depend on the thread
// count, a poorly numbered packing is renumbered along a Morton curve (ids, clumps and physics
// kept), and a well numbered one is left alone. Units: SI.
#include "core/model.hpp"
#include "helpers.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <set>

namespace rocklab::test {
namespace {

/// An FCC block of about n spheres (R = 1 mm) whose 12 neighbours overlap slightly, bonded with
/// parallel bonds weak enough that the random velocities break some (events, changing contacts),
/// numbered in lattice order or shuffled.
Model bonded_block(std::size_t n, bool shuffled) {
  Model m;
  m.settings.dim = 3;
  const double R = 1e-3, a = 2 * std::sqrt(2.0) * R * (1 - 0.5e-5);
  const int cells = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(n) / 4.0)));
  const Vec3 basis[4] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  std::vector<Vec3> x;
  for (int i = 0; i < cells; ++i)
    for (int j = 0; j < cells; ++j)
      for (int k = 0; k < cells; ++k)
        for (const Vec3& b : basis)
          if (x.size() < n)
            x.push_back(a * (Vec3(i, j, k) + b));
  std::vector<std::size_t> order(x.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  if (shuffled)
    std::shuffle(order.begin(), order.end(), std::mt19937_64(3));
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Vec3> v(x.size());
  for (Vec3& vi : v)
    vi = Vec3(u(rng), u(rng), u(rng)) * 0.05;
  for (std::size_t k : order) { // each ball keeps its velocity whatever its place
    const std::size_t b = m.balls.add(3, static_cast<std::int64_t>(k) + 1, x[k], R, 2650, 0);
    m.balls.vel[b] = v[k];
  }
  LinearPBondProps p;
  p.linear.emod = 1e9;
  p.linear.kratio = 1.5;
  p.linear.fric = 0.5;
  p.pb_emod = 1e9;
  p.pb_kratio = 1.5;
  p.pb_ten = p.pb_coh = 2e6;
  p.bond = true;
  p.bond_gap_hi = 1e-4;
  ModelRule rule;
  rule.props = p;
  m.rules.push_back(rule);
  return m;
}

struct Snapshot {
  std::vector<Vec3> pos, vel, spin;
  std::vector<double> energy;
  std::size_t contacts = 0, events = 0;
};

Snapshot run_with_threads(int threads, std::int64_t cycles,
                          const std::vector<double>& shares = {}) {
  const int before = omp_get_max_threads();
  omp_set_num_threads(threads);
  Model m = bonded_block(3000, true);
  m.renumber_spatially();
  if (!shares.empty())
    m.set_thread_shares(shares);
  m.initialize();
  m.cycle(cycles);
  std::vector<Event> ev;
  m.drain_events(ev);
  omp_set_num_threads(before);
  const EnergyLedger e = m.energy();
  return {
      m.balls.pos,         m.balls.vel,
      m.balls.spin,        {e.kinetic(), e.stored(), e.local_damping, e.bond_break, e.body_work},
      m.contacts().size(), ev.size()};
}

} // namespace

TEST(Parallel, AThreeThousandGrainBondedBlockGivesTheSameBitsAtOneTwoAndThreeThreads) {
  const Snapshot one = run_with_threads(1, 300);
  EXPECT_GT(one.events, 0u); // bonds broke: events and changing contacts are part of the check
  for (int threads : {2, 3}) {
    const Snapshot other = run_with_threads(threads, 300);
    EXPECT_EQ(one.contacts, other.contacts) << threads;
    EXPECT_EQ(one.events, other.events) << threads;
    EXPECT_TRUE(one.pos == other.pos) << threads << " threads: positions differ";
    EXPECT_TRUE(one.vel == other.vel) << threads << " threads: velocities differ";
    EXPECT_TRUE(one.spin == other.spin) << threads << " threads: spins differ";
    EXPECT_TRUE(one.energy == other.energy) << threads << " threads: energies differ";
  }
}

// The shares follow the threads' measured speeds, so a plan can be anything: a lopsided one (a
// thread with 90 % of the work, its boundary inside a reduction block) gives the same bits too.
TEST(Parallel, LopsidedThreadSharesGiveTheSameBits) {
  const Snapshot even = run_with_threads(2, 150);
  const Snapshot lopsided = run_with_threads(2, 150, {0.9, 0.1});
  const Snapshot three = run_with_threads(3, 150, {0.2, 0.05, 0.75});
  EXPECT_TRUE(even.pos == lopsided.pos && even.vel == lopsided.vel && even.spin == lopsided.spin);
  EXPECT_TRUE(even.energy == lopsided.energy);
  EXPECT_TRUE(even.pos == three.pos && even.vel == three.vel && even.energy == three.energy);
  EXPECT_THROW(Model().set_thread_shares({1.0, 0.0}), std::invalid_argument);
}

TEST(Parallel, AShuffledPackingIsRenumberedAlongAMortonCurveKeepingIdsAndPhysics) {
  Model lattice = bonded_block(2000, false), shuffled = bonded_block(2000, true);
  EXPECT_FALSE(lattice.renumber_spatially()); // lattice order is spatial already: left alone
  for (std::size_t i = 0; i < lattice.balls.size(); ++i)
    ASSERT_EQ(lattice.balls.id[i], static_cast<std::int64_t>(i) + 1);
  auto mean_step = [](const Model& m) {
    double s = 0;
    for (std::size_t i = 1; i < m.balls.size(); ++i)
      s += (m.balls.pos[i] - m.balls.pos[i - 1]).norm();
    return s / static_cast<double>(m.balls.size() - 1) / 1e-3; // in radii
  };
  EXPECT_GT(mean_step(shuffled), 8.0);
  ASSERT_TRUE(shuffled.renumber_spatially());
  EXPECT_LT(mean_step(shuffled), 3.0);
  std::set<std::int64_t> ids(shuffled.balls.id.begin(), shuffled.balls.id.end());
  EXPECT_EQ(ids.size(), 2000u);
  EXPECT_EQ(*ids.begin(), 1);
  EXPECT_EQ(*ids.rbegin(), 2000);
  // Every ball keeps its own state under its id, and the motion is the same physics: the same
  // balls after 100 steps to round-off (sums run in another order, so not to the bit; bonds
  // break, which amplifies round-off: speeds are about 0.05 m/s).
  lattice.initialize();
  shuffled.initialize();
  lattice.cycle(100);
  shuffled.cycle(100);
  for (std::size_t i = 0; i < shuffled.balls.size(); ++i) {
    const std::size_t j = static_cast<std::size_t>(shuffled.balls.id[i] - 1);
    ASSERT_LT((shuffled.balls.pos[i] - lattice.balls.pos[j]).norm(), 1e-12) << "id " << j + 1;
    ASSERT_LT((shuffled.balls.vel[i] - lattice.balls.vel[j]).norm(), 1e-7) << "id " << j + 1;
  }
  EXPECT_EQ(shuffled.contacts().size(), lattice.contacts().size());
  EXPECT_THROW(shuffled.renumber_balls({}), std::logic_error); // only before initialize()
}

TEST(Parallel, RenumberingKeepsEachClumpsPebblesWithTheirOffsets) {
  Model m;
  m.settings.dim = 3;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 0.2);
  std::vector<Vec3> centres;
  for (int k = 0; k < 520; ++k)
    centres.emplace_back(u(rng), u(rng), u(rng));
  for (int k = 0; k < 520; ++k) // two-pebble clumps, numbered in random places
    m.add_clump({{centres[static_cast<std::size_t>(k)], 1e-3},
                 {centres[static_cast<std::size_t>(k)] + Vec3(1e-3, 0, 0), 1e-3}},
                2650, 0, k + 1, 2 * k + 1, Vec3::Zero(), Vec3::Zero());
  ASSERT_TRUE(m.renumber_spatially());
  for (std::size_t k = 0; k < m.clumps.size(); ++k) {
    const Clump& c = m.clumps[k];
    for (std::size_t a = 0; a < c.pebbles.size(); ++a) {
      const std::size_t i = static_cast<std::size_t>(c.pebbles[a]);
      EXPECT_EQ(m.balls.clump[i], static_cast<std::int32_t>(k));
      EXPECT_LT((m.balls.pos[i] - (c.pos + c.q * c.offset[a])).norm(), 1e-12);
      EXPECT_EQ(m.balls.id[i], 2 * c.id - 1 + static_cast<std::int64_t>(a));
    }
  }
}

} // namespace rocklab::test
