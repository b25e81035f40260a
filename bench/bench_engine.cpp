// Throughput of the engine cycle. Counters: contact-updates/s (contacts in the list times
// cycles per second), particle-steps/s (balls times cycles per second). Units: SI.
#include "core/model.hpp"
#include "core/spatial_order.hpp"

#include <benchmark/benchmark.h>
#include <omp.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <map>
#include <numeric>
#include <random>
#include <string>

using namespace rocklab;

namespace {

/// A dense 3D packing near equilibrium: an FCC lattice of n balls of radius R whose 12 nearest
/// neighbours overlap by 1e-5 R (all contacts active, like a confined bonded specimen), with
/// small random velocities so contacts really load and unload.
Model dense_packing(std::size_t n_target, ModelProps props) {
  Model m;
  m.settings.dim = 3;
  m.settings.local_damping = 0.7;
  const double R = 1e-3;
  const double a = 2 * std::sqrt(2.0) * R * (1 - 0.5e-5); // FCC cube edge
  const int cells = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(n_target) / 4.0)));
  const Vec3 basis[4] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  std::int64_t id = 1;
  for (int i = 0; i < cells; ++i)
    for (int j = 0; j < cells; ++j)
      for (int k = 0; k < cells; ++k)
        for (const Vec3& b : basis) {
          if (m.balls.size() >= n_target)
            break;
          const Vec3 x = a * (Vec3(i, j, k) + b);
          const std::size_t ball = m.balls.add(3, id++, x, R, 2650, 0);
          m.balls.vel[ball] = Vec3(u(rng), u(rng), u(rng)) * 1e-4;
        }
  ModelRule rule;
  rule.props = props;
  m.rules.push_back(rule);
  m.initialize();
  return m;
}

void run_cycles(benchmark::State& state, Model& m) {
  omp_set_num_threads(static_cast<int>(state.range(0)));
  m.cycle(10); // warm-up: first detections, buffers at size
  std::int64_t cycles = 0;
  double contacts = 0;
  for (auto _ : state) {
    m.cycle(1);
    ++cycles;
    contacts += static_cast<double>(m.contacts().size());
  }
  state.counters["contacts"] = static_cast<double>(m.contacts().size());
  state.counters["contact_updates_per_s"] =
      benchmark::Counter(contacts, benchmark::Counter::kIsRate);
  state.counters["particle_steps_per_s"] =
      benchmark::Counter(static_cast<double>(cycles) * static_cast<double>(m.balls.size()),
                         benchmark::Counter::kIsRate);
}

void BM_LinearDense3D_20k(benchmark::State& state) {
  LinearProps p;
  p.emod = 1e9;
  p.kratio = 1.5;
  p.fric = 0.5;
  static Model m = dense_packing(20000, p);
  run_cycles(state, m);
}

// The bonded models on the same packing: bonds installed at every contact, strengths high
// enough that nothing breaks (this measures the elastic cycle).
LinearPBondProps pb_bench_props(double emod, double kratio) {
  LinearPBondProps p;
  p.linear.emod = p.pb_emod = emod;
  p.linear.kratio = p.pb_kratio = kratio;
  p.linear.fric = 0.5;
  p.pb_ten = p.pb_coh = 1e12;
  p.bond = true;
  return p;
}

void BM_PBondDense3D_20k(benchmark::State& state) {
  LinearPBondProps p = pb_bench_props(1e9, 1.5);
  p.bond_gap_hi = 1e-4;
  static Model m = dense_packing(20000, p);
  run_cycles(state, m);
}

FlatJointProps fj_bench_props(bool exact) {
  FlatJointProps p; // N_r = 2, N_alpha = 4: 8 elements
  p.fj_emod = 1e9;
  p.fj_kratio = 1.5;
  p.fj_ten = p.fj_coh = 1e12;
  p.fj_fric = 0.5;
  p.bond = true;
  p.fj_exact = exact;
  return p;
}

void BM_FlatJoint8Dense3D_20k(benchmark::State& state) {
  static Model m = dense_packing(20000, fj_bench_props(false));
  run_cycles(state, m);
}

void BM_FlatJoint8ExactDense3D_20k(benchmark::State& state) {
  static Model m = dense_packing(20000, fj_bench_props(true));
  run_cycles(state, m);
}

void BM_SmoothJointDense3D_20k(benchmark::State& state) {
  SmoothJointProps p;
  p.sj_kn = 1e12;
  p.sj_ks = 5e11;
  p.sj_fric = 0.5;
  p.dip = 30;
  p.ddir = 45;
  static Model m = dense_packing(20000, p);
  run_cycles(state, m);
}

// A ~10k-grain bonded packing as users bring it: another code's packing (x y z r per line, e.g.
// YADE's SpherePack.save; bench/race/race.sh makes one with YADE) in its given order (0),
// renumbered along a Morton curve (1) or shuffled (2), each loaded as a scene loads it (renumbered
// when its order is poor, Model::renumber_spatially), and the given (3) and shuffled (4) orders
// as the cycle gets them without that. The pairs within 0.1 (R1 + R2) are bonded
// (YADE JCFpm's interaction factor 1.1), strengths high so nothing breaks; small random
// velocities so the contacts load and unload. The file is ROCKLAB_BENCH_PACKING, by default
// race.sh's /tmp/rocklab-race/packing.txt; the cases are skipped without it.
enum class Order { Given = 0, Spatial = 1, Shuffled = 2, GivenRaw = 3, ShuffledRaw = 4 };

std::vector<std::array<double, 4>> read_packing() {
  const char* env = std::getenv("ROCKLAB_BENCH_PACKING");
  std::ifstream in(env ? env : "/tmp/rocklab-race/packing.txt");
  std::vector<std::array<double, 4>> rows;
  std::string line;
  while (std::getline(in, line)) {
    std::array<double, 4> r{};
    if (std::sscanf(line.c_str(), "%lf %lf %lf %lf", &r[0], &r[1], &r[2], &r[3]) == 4)
      rows.push_back(r);
  }
  return rows;
}

Model packing_model(Order order, ModelProps props) {
  auto rows = read_packing();
  Model m;
  if (rows.empty())
    return m;
  m.settings.dim = 3;
  m.settings.local_damping = 0.7;
  m.settings.slip_events = false; // as in the lab's tests: they read bond breaks only
  std::vector<Vec3> x(rows.size());
  double r_avg = 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    x[i] = Vec3(rows[i][0], rows[i][1], rows[i][2]);
    r_avg += rows[i][3] / static_cast<double>(rows.size());
  }
  std::vector<std::size_t> perm(rows.size());
  std::iota(perm.begin(), perm.end(), std::size_t{0});
  if (order == Order::Spatial)
    perm = morton_order(x, 3, 2 * r_avg);
  else if (order == Order::Shuffled || order == Order::ShuffledRaw)
    std::shuffle(perm.begin(), perm.end(), std::mt19937_64(7));
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  for (std::size_t k = 0; k < perm.size(); ++k) {
    const auto& r = rows[perm[k]];
    const std::size_t ball = m.balls.add(3, static_cast<std::int64_t>(perm[k]) + 1,
                                         Vec3(r[0], r[1], r[2]), r[3], 2650, 0);
    m.balls.vel[ball] = Vec3(u(rng), u(rng), u(rng)) * 1e-4;
  }
  ModelRule rule;
  rule.props = props;
  m.rules.push_back(rule);
  // As a scene loads it (docs/scene-format.md, "Numbering"); the raw orders show the cycle alone.
  if (order != Order::GivenRaw && order != Order::ShuffledRaw)
    m.renumber_spatially();
  m.settings.margin = 0.21 * 2 * r_avg; // finds every pair within 0.1 (R1 + R2)
  m.initialize();
  m.set_margin(0.1 * r_avg); // the unbonded far pairs go; the bonds keep their contacts
  return m;
}

void run_packing(benchmark::State& state, Model& m) {
  if (m.balls.size() == 0) {
    state.SkipWithError("no packing: set ROCKLAB_BENCH_PACKING (x y z r per line)");
    return;
  }
  run_cycles(state, m);
}

LinearPBondProps pb_packing_props() {
  LinearPBondProps p = pb_bench_props(7e10, 2.0);
  p.bond_gap_ratio = true;
  p.bond_gap_hi = 0.1;
  return p;
}

FlatJointProps fj_packing_props() {
  FlatJointProps p = fj_bench_props(false);
  p.fj_emod = 7e10;
  p.fj_kratio = 2.0;
  p.bond_gap_ratio = true;
  p.bond_gap_hi = 0.1;
  return p;
}

// One model per order and contact model, made at its first case.
template <class Props> void run_packing_order(benchmark::State& state, Props (*props)()) {
  static std::map<std::int64_t, Model> models;
  const std::int64_t order = state.range(1);
  if (!models.count(order))
    models.emplace(order, packing_model(static_cast<Order>(order), props()));
  run_packing(state, models.at(order));
}

void BM_PBondPacking10k(benchmark::State& state) {
  run_packing_order(state, pb_packing_props);
}

void BM_FlatJoint8Packing10k(benchmark::State& state) {
  run_packing_order(state, fj_packing_props);
}

// The bare-kernel ceiling: the contact law alone (the model's update and its stiffness, what
// update_contact_force calls) over the same contacts, their kinematics packed in one array made
// beforehand, with no contact plane, ball reads or force sums. Small elastic increments, their
// sign alternating between passes so nothing drifts or breaks. The full cycle's time per contact
// over this case's is the fraction of the kernel the cycle reaches (docs/performance.md).
void run_kernel(benchmark::State& state, const Model& m) {
  if (m.balls.size() == 0) {
    state.SkipWithError("no packing: set ROCKLAB_BENCH_PACKING (x y z r per line)");
    return;
  }
  omp_set_num_threads(static_cast<int>(state.range(0)));
  ModelBatches batches = m.batches();
  const auto& cs = m.contacts();
  std::vector<ContactKinematics> kin(cs.size());
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(-1, 1);
  for (std::size_t ci = 0; ci < cs.size(); ++ci) {
    const Contact& c = cs[ci];
    ContactKinematics& k = kin[ci];
    const std::size_t i1 = static_cast<std::size_t>(c.end1);
    k.dt = 1e-8;
    k.dim = 3;
    k.gap = c.gap;
    k.R1 = m.balls.radius[i1];
    k.ball_facet = c.kind == ContactKind::BallFacet;
    k.R2 = k.ball_facet ? 0.0 : m.balls.radius[static_cast<std::size_t>(c.end2)];
    k.mass_eff = m.balls.mass[i1] / 2;
    k.n = c.n, k.s = c.s, k.t = c.t;
    const double d = 1e-10 * k.R1 / 1e-3, a = 1e-8;
    k.d_dn = d * u(rng), k.d_dss = d * u(rng), k.d_dst = d * u(rng);
    k.d_tt = a * u(rng), k.d_tbs = a * u(rng), k.d_tbt = a * u(rng);
  }
  std::vector<ContactResult> out(cs.size());
  std::vector<ContactStiffness> stiff(cs.size());
  std::vector<EventBuffer> events(static_cast<std::size_t>(omp_get_max_threads()));
  auto pass = [&] {
#pragma omp parallel for schedule(static)
    for (std::size_t ci = 0; ci < cs.size(); ++ci) {
      ContactKinematics& k = kin[ci];
      EventSink sink{&events[static_cast<std::size_t>(omp_get_thread_num())], cs[ci].key, 0,
                     m.settings.slip_events};
      update_contact(batches, cs[ci].model, cs[ci].slot, k, out[ci], sink);
      stiff[ci] = contact_stiffness(batches, cs[ci].model, cs[ci].slot);
      k.d_dn = -k.d_dn, k.d_dss = -k.d_dss, k.d_dst = -k.d_dst;
      k.d_tt = -k.d_tt, k.d_tbs = -k.d_tbs, k.d_tbt = -k.d_tbt;
    }
    for (auto& e : events)
      e.clear();
  };
  pass();
  for (auto _ : state) {
    pass();
    benchmark::DoNotOptimize(out.data());
    benchmark::DoNotOptimize(stiff.data());
  }
  state.counters["contacts"] = static_cast<double>(cs.size());
  state.counters["contact_updates_per_s"] =
      benchmark::Counter(static_cast<double>(cs.size()) * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate);
}

void BM_PBondKernel10k(benchmark::State& state) {
  static Model m = packing_model(Order::Spatial, pb_packing_props());
  run_kernel(state, m);
}

void BM_FlatJoint8Kernel10k(benchmark::State& state) {
  static Model m = packing_model(Order::Spatial, fj_packing_props());
  run_kernel(state, m);
}

void configure(benchmark::internal::Benchmark* b) {
  b->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond)->MinTime(3.0);
}

// Threads 1 and 2 for each order: given (0), spatial (1), shuffled (2), and not renumbered at
// load: given (3), shuffled (4).
void configure_orders(benchmark::internal::Benchmark* b) {
  b->ArgNames({"threads", "order"});
  for (int order : {0, 1, 2, 3, 4})
    for (int threads : {1, 2})
      b->Args({threads, order});
  b->UseRealTime()->Unit(benchmark::kMillisecond)->MinTime(3.0);
}

} // namespace

BENCHMARK(BM_PBondPacking10k)->Apply(configure_orders);
BENCHMARK(BM_FlatJoint8Packing10k)->Apply(configure_orders);
BENCHMARK(BM_PBondKernel10k)->Apply(configure);
BENCHMARK(BM_FlatJoint8Kernel10k)->Apply(configure);
BENCHMARK(BM_LinearDense3D_20k)->Apply(configure);
BENCHMARK(BM_PBondDense3D_20k)->Apply(configure);
BENCHMARK(BM_FlatJoint8Dense3D_20k)->Apply(configure);
BENCHMARK(BM_FlatJoint8ExactDense3D_20k)->Apply(configure);
BENCHMARK(BM_SmoothJointDense3D_20k)->Apply(configure);

BENCHMARK_MAIN();
