#include "io/work_estimate.hpp"

#include "io/input_error.hpp"

#include <omp.h>
#include <unistd.h>

#include <cstdio>
#include <iomanip>
#include <sstream>

namespace rocklab {

namespace {

// The cycle's cost on one core of the reference machine (2-core AMD EPYC, docs/performance.md),
// between a settling linear packing (examples/settling_2k.json: 2,000 grains x 4,000 steps in
// 0.78 s, 1.0e-7 s a grain-step) and the flat-jointed granite of the README's main job (about
// 8e-7 s a grain-step), and per step of a model of a few grains (examples/ball_drop.json and
// verification/interlocked_3d.json: 7.7 and 9.3 us a step).
constexpr double kSecondsPerBallStep = 3e-7;
constexpr double kSecondsPerStep = 8e-6;
constexpr double kWarnSeconds = 3600;

std::string num(double v) {
  return message_number(v, 3);
}

std::string duration(double s) {
  if (s < 120)
    return num(s) + " s";
  if (s < 7200)
    return num(s / 60) + " min";
  if (s < 2 * 86400)
    return num(s / 3600) + " h";
  return num(s / 86400) + " days";
}

} // namespace

std::string message_number(double v, int digits) {
  std::ostringstream s;
  s << std::setprecision(digits) << v;
  return s.str();
}

double physical_memory() {
  const long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && size > 0 ? static_cast<double>(pages) * static_cast<double>(size) : 0;
}

double estimated_seconds(const WorkEstimate& e, int threads) {
  const double t = threads > 1 ? 0.6 * threads : 1.0; // the second thread adds about 1.2x
  return (e.ball_steps * kSecondsPerBallStep + e.steps * kSecondsPerStep) / t;
}

void check_estimate(const WorkEstimate& e, const std::string& file, const std::string& key,
                    bool quiet) {
  const double ram = physical_memory();
  if (ram > 0 && e.bytes > 0.8 * ram)
    throw InputError(file + ": key '" + key + "': the run asks for about " + num(e.steps) +
                     " steps whose records need about " + num(e.bytes / 1e9) +
                     " GB; allowed: within 80 % of this machine's " + num(ram / 1e9) +
                     " GB (fewer steps, a larger time step or fewer history rows)");
  const int threads = omp_get_max_threads();
  const double seconds = estimated_seconds(e, threads);
  if (!quiet)
    std::printf("estimate     %s steps (%s grain-steps%s), records %s MB: about %s on %d "
                "thread(s)\n",
                num(e.steps).c_str(), num(e.ball_steps).c_str(),
                e.open_ended ? ", and the stages that stop on a condition" : "",
                num(e.bytes / 1e6).c_str(), duration(seconds).c_str(), threads);
  if (seconds > kWarnSeconds)
    std::fprintf(stderr,
                 "warning: %s: key '%s' asks for %s steps (%s grain-steps): about %s on %d "
                 "thread(s); Ctrl-C stops it with nothing written\n",
                 file.c_str(), key.c_str(), num(e.steps).c_str(), num(e.ball_steps).c_str(),
                 duration(seconds).c_str(), threads);
}

void warn_projection(const std::string& file, double fraction, double wall) {
  const double total = wall / fraction;
  if (total > kWarnSeconds)
    std::fprintf(stderr,
                 "warning: %s: %.3g %% done in %s: at this pace the stage takes about %s; "
                 "Ctrl-C stops it with nothing written\n",
                 file.c_str(), 100 * fraction, duration(wall).c_str(), duration(total).c_str());
}

} // namespace rocklab
