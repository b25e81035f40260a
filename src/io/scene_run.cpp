#include "io/scene_run.hpp"

#include "io/output_dir.hpp"
#include "io/progress.hpp"
#include "io/results.hpp"
#include "io/work_estimate.hpp"

#include <chrono>
#include <cstdio>
#include <stdexcept>

namespace rocklab {

namespace {

// How far a stage is: the fraction of its cycles or of its time; -1 for a stage that stops on the
// unbalanced-force ratio.
double stage_fraction(const RunSpec& run, const Model& m, std::int64_t step0, double time0) {
  if (run.cycles > 0)
    return static_cast<double>(m.step() - step0) / static_cast<double>(run.cycles);
  if (run.time > 0)
    return (m.time() - time0) / run.time;
  return -1;
}

// The state of a running stage: its step and time, and how far it is (cycles or time) or its
// unbalanced-force ratio; the ETA only for a one-stage scene, where the fraction is the run's.
void show_progress(ProgressLine& line, const Scene& scene, std::size_t stage, const Model& m,
                   std::int64_t step0, double time0) {
  const RunSpec& run = scene.stages[stage].run;
  const double frac = stage_fraction(run, m, step0, time0);
  char buf[160];
  const int n = std::snprintf(buf, sizeof buf, "stage %zu/%zu  step %lld  t %.4g s  ", stage + 1,
                              scene.stages.size(), static_cast<long long>(m.step()), m.time());
  if (frac >= 0)
    std::snprintf(buf + n, sizeof buf - static_cast<std::size_t>(n), "%.1f%%", 100.0 * frac);
  else
    std::snprintf(buf + n, sizeof buf - static_cast<std::size_t>(n), "ratio %.3g",
                  m.mean_unbalanced_force_ratio(true));
  line.show(buf, scene.stages.size() == 1 ? frac : -1);
}

// The history's text for `steps` more steps (about 24 bytes a value) [bytes].
double history_bytes(const Scene& scene, double steps) {
  if (scene.history.empty())
    return 0;
  return (steps / static_cast<double>(scene.history_every) + 2) *
         (24.0 * static_cast<double>(scene.history.size()) + 1);
}

// The steps every stage asks for at the time step the model starts with (a stage that stops on
// the unbalanced-force ratio counts at its max_cycles, or not at all without one) and the
// history's text.
WorkEstimate scene_estimate(const Scene& scene, const Model& m) {
  WorkEstimate e;
  const double dt = m.estimate_timestep();
  for (const Stage& st : scene.stages) {
    if (st.run.cycles > 0)
      e.steps += static_cast<double>(st.run.cycles);
    else if (st.run.time > 0 && dt > 0)
      e.steps += st.run.time / dt;
    else if (st.run.max_cycles > 0)
      e.steps += static_cast<double>(st.run.max_cycles);
    else
      e.open_ended = true;
  }
  e.ball_steps = e.steps * static_cast<double>(m.balls.size());
  e.bytes = history_bytes(scene, e.steps);
  return e;
}

} // namespace

RunSummary run_scene(Scene& scene, const RunOptions& opts) {
  using clock = std::chrono::steady_clock;
  OutputDir out(opts.out_dir);
  Model& m = *scene.model;
  RunSummary summary;
  const auto t0 = clock::now();
  ProgressLine progress("run", opts.progress);

  m.initialize();
  check_estimate(scene_estimate(scene, m), scene.file, scene.history.empty() ? "run" : "history",
                 !opts.progress);
  std::vector<Event> events;
  m.drain_events(events);
  summary.events.add(events);

  std::string history;
  const bool want_history = !scene.history.empty();
  if (want_history) {
    history = history_header(scene.history);
    history += history_row(m, scene.history, summary.events);
  }

  std::size_t stage_index = 0;
  for (const Stage& stage : scene.stages) {
    for (const BallChange& bc : stage.set) {
      if (bc.velocity)
        m.balls.vel[bc.index] = *bc.velocity;
      if (bc.spin)
        m.balls.spin[bc.index] = *bc.spin;
      m.balls.fixity[bc.index] =
          static_cast<std::uint8_t>((m.balls.fixity[bc.index] | bc.fix) & ~bc.free);
    }
    for (const MethodCall& mc : stage.methods)
      m.apply_method(mc.model, mc.method, mc.gap_lo, mc.gap_hi, mc.element, mc.gap_ratio);
    const RunSpec& run = stage.run;
    const std::int64_t step0 = m.step();
    const double time0 = m.time();
    auto done = [&]() {
      const std::int64_t steps = m.step() - step0;
      if (run.cycles > 0)
        return steps >= run.cycles;
      if (run.max_cycles > 0 && steps >= run.max_cycles)
        return true;
      if (run.time > 0)
        return m.time() - time0 >= run.time;
      // Not before the first cycle: the forces and moments are computed there.
      if (steps == 0 || steps % run.check_every != 0)
        return false;
      return m.mean_unbalanced_force_ratio(true) < run.ratio;
    };
    const auto stage_t0 = clock::now();
    bool projected = false; // the stage's projected wall time was checked
    while (!done()) {
      if (opts.interrupt && opts.interrupt->load())
        throw std::runtime_error("interrupted; nothing was written to " + opts.out_dir);
      m.cycle(1);
      // A stiffness that acts only once contacts form shrinks the time step after set-up (a
      // stiff floor under a falling ball): after a minute, the stage's measured pace is
      // projected to its end and warned about like the set-up's estimate.
      if (!projected && m.step() % 1024 == 0) {
        const double wall = std::chrono::duration<double>(clock::now() - stage_t0).count();
        const double frac = stage_fraction(run, m, step0, time0);
        if (wall > 60 && frac > 0) {
          projected = true;
          warn_projection(scene.file, frac, wall);
        }
      }
      events.clear();
      m.drain_events(events);
      summary.events.add(events);
      if (want_history && m.step() % scene.history_every == 0)
        history += history_row(m, scene.history, summary.events);
      if (m.step() % 64 == 0 && progress.due())
        show_progress(progress, scene, stage_index, m, step0, time0);
    }
    ++stage_index;
  }
  progress.finish();
  if (want_history && m.step() % scene.history_every != 0)
    history += history_row(m, scene.history, summary.events);

  write_file(out.staged("results.json"), [&](std::ostream& os) {
    write_results_json(os, m, summary.events, scene.file, scene.contacts_output);
  });
  if (want_history)
    write_text_file(out.staged("history.csv"), history);
  else
    write_text_file(out.staged("history.csv"), "step,time\n" + std::to_string(m.step()) + "," +
                                                   format_double(m.time()) + "\n");
  out.commit();
  summary.steps = m.step();
  summary.time = m.time();
  summary.wall_seconds = std::chrono::duration<double>(clock::now() - t0).count();
  return summary;
}

} // namespace rocklab
