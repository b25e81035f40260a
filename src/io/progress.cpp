#include "io/progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace rocklab {

namespace {
constexpr int kWidth = 80;             ///< terminal columns a line may take
constexpr double kTerminalEvery = 0.5; ///< [s]
constexpr double kLogEvery = 10.0;     ///< [s]

// The log interval: ROCKLAB_PROGRESS_SECONDS (a positive number of seconds) or 10 s.
double log_every() {
  if (const char* v = std::getenv("ROCKLAB_PROGRESS_SECONDS")) {
    char* end = nullptr;
    const double s = std::strtod(v, &end);
    if (end != v && *end == '\0' && s > 0 && std::isfinite(s))
      return s;
  }
  return kLogEvery;
}
thread_local std::function<void(const ProgressEvent&)> t_sink;

} // namespace

ProgressSink::ProgressSink(std::function<void(const ProgressEvent&)> sink) {
  t_sink = std::move(sink);
}

ProgressSink::~ProgressSink() {
  t_sink = nullptr;
}

ProgressLine::ProgressLine(std::string tag, bool enabled, int terminal)
    : tag_(std::move(tag)), sink_(t_sink), enabled_(enabled),
      terminal_(sink_ || (terminal < 0 ? ::isatty(STDERR_FILENO) != 0 : terminal != 0)),
      log_every_(log_every()), start_(clock::now()), last_(start_) {}

ProgressLine::~ProgressLine() {
  finish();
}

bool ProgressLine::due() const {
  if (!enabled_)
    return false;
  const auto now = clock::now();
  const double since_start = std::chrono::duration<double>(now - start_).count();
  const double since_last = std::chrono::duration<double>(now - last_).count();
  if (terminal_)
    return since_start > 1.0 && (since_last > kTerminalEvery || !shown_);
  return since_last > log_every_;
}

std::string ProgressLine::duration(double s) {
  char buf[32];
  const long t = std::lround(std::max(0.0, s));
  if (t < 60)
    std::snprintf(buf, sizeof buf, "%lds", t);
  else if (t < 3600)
    std::snprintf(buf, sizeof buf, "%ldm%02lds", t / 60, t % 60);
  else
    std::snprintf(buf, sizeof buf, "%ldh%02ldm", t / 3600, (t % 3600) / 60);
  return buf;
}

std::string ProgressLine::format(const std::string& what, double elapsed_s, double eta_s,
                                 int width) const {
  // The times before the state: a long state is cut at the width, never the times.
  std::string line = "[rocklab " + tag_ + "] " + duration(elapsed_s);
  if (eta_s >= 0)
    line += ", ETA " + duration(eta_s);
  line += "  " + what;
  if (width > 0 && static_cast<int>(line.size()) > width)
    line.resize(static_cast<std::size_t>(width));
  return line;
}

void ProgressLine::show(const std::string& what, double fraction) {
  if (!enabled_)
    return;
  last_ = clock::now();
  shown_ = true;
  const double elapsed = std::chrono::duration<double>(last_ - start_).count();
  // The rate of the fraction since it began (or fell back: a new stretch, e.g. a load that
  // recovered toward its peak), so that time spent before it was known does not count.
  double eta = -1;
  if (fraction >= 0) {
    if (!have_ref_ || fraction < ref_fraction_) {
      have_ref_ = true;
      ref_fraction_ = fraction;
      ref_time_ = last_;
    }
    const double dt = std::chrono::duration<double>(last_ - ref_time_).count();
    if (fraction < 1 && fraction > ref_fraction_ && dt > 2)
      eta = dt * (1 - fraction) / (fraction - ref_fraction_);
  }
  if (sink_) {
    sink_({tag_, what, fraction, elapsed, eta});
    return;
  }
  if (terminal_) {
    // One column short of the width: a full-width line makes some terminals wrap at once.
    std::string line = format(what, elapsed, eta, kWidth - 1);
    line.resize(static_cast<std::size_t>(kWidth - 1), ' ');
    std::fprintf(stderr, "\r%s", line.c_str());
    pending_ = true;
  } else {
    std::fprintf(stderr, "%s\n", format(what, elapsed, eta, 0).c_str());
  }
  std::fflush(stderr);
}

void ProgressLine::finish() {
  if (pending_) {
    std::fprintf(stderr, "\n");
    std::fflush(stderr);
    pending_ = false;
  }
}

} // namespace rocklab
