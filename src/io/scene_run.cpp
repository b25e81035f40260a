#include "io/scene_run.hpp"

#include "io/output_dir.hpp"
#include "io/results.hpp"

#include <chrono>
#include <cstdio>
#include <stdexcept>

namespace rocklab {

RunSummary run_scene(Scene& scene, const RunOptions& opts) {
  using clock = std::chrono::steady_clock;
  OutputDir out(opts.out_dir);
  Model& m = *scene.model;
  RunSummary summary;
  const auto t0 = clock::now();
  auto last_print = t0;

  m.initialize();
  std::vector<Event> events;
  m.drain_events(events);
  summary.events.add(events);

  std::string history;
  const bool want_history = !scene.history.empty();
  if (want_history) {
    history = history_header(scene.history);
    history += history_row(m, scene.history, summary.events);
  }

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
    while (!done()) {
      if (opts.interrupt && opts.interrupt->load())
        throw std::runtime_error("interrupted; nothing was written to " + opts.out_dir);
      m.cycle(1);
      events.clear();
      m.drain_events(events);
      summary.events.add(events);
      if (want_history && m.step() % scene.history_every == 0)
        history += history_row(m, scene.history, summary.events);
      if (opts.progress) {
        const auto now = clock::now();
        if (now - t0 > std::chrono::seconds(2) &&
            now - last_print > std::chrono::milliseconds(500)) {
          last_print = now;
          double frac = -1;
          if (run.cycles > 0)
            frac = static_cast<double>(m.step() - step0) / static_cast<double>(run.cycles);
          else if (run.time > 0)
            frac = (m.time() - time0) / run.time;
          if (frac >= 0)
            std::fprintf(stderr, "\r[rocklab] step %lld  t = %.4g s  %5.1f%%   ",
                         static_cast<long long>(m.step()), m.time(), 100.0 * frac);
          else
            std::fprintf(stderr, "\r[rocklab] step %lld  t = %.4g s  ratio %.3g   ",
                         static_cast<long long>(m.step()), m.time(),
                         m.mean_unbalanced_force_ratio(true));
          std::fflush(stderr);
        }
      }
    }
  }
  if (opts.progress && clock::now() - t0 > std::chrono::seconds(2))
    std::fprintf(stderr, "\n");
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
