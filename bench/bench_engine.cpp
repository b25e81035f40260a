// Throughput of the engine cycle. Counters: contact-updates/s (contacts in the list times
// cycles per second), particle-steps/s (balls times cycles per second). Units: SI.
#include "core/model.hpp"

#include <benchmark/benchmark.h>
#include <omp.h>

#include <random>

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
void BM_PBondDense3D_20k(benchmark::State& state) {
  LinearPBondProps p;
  p.linear.emod = 1e9;
  p.linear.kratio = 1.5;
  p.linear.fric = 0.5;
  p.pb_emod = 1e9;
  p.pb_kratio = 1.5;
  p.pb_ten = p.pb_coh = 1e12;
  p.bond = true;
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

void configure(benchmark::internal::Benchmark* b) {
  b->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond)->MinTime(3.0);
}

} // namespace

BENCHMARK(BM_LinearDense3D_20k)->Apply(configure);
BENCHMARK(BM_PBondDense3D_20k)->Apply(configure);
BENCHMARK(BM_FlatJoint8Dense3D_20k)->Apply(configure);
BENCHMARK(BM_FlatJoint8ExactDense3D_20k)->Apply(configure);
BENCHMARK(BM_SmoothJointDense3D_20k)->Apply(configure);

BENCHMARK_MAIN();
