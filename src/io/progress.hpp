// Progress lines a person can live with, on stderr. On a terminal: one line rewritten in place,
// never wider than 80 columns, with the elapsed time and, where the fraction done is known, an
// estimate of the time left. When stderr is a file or a pipe (a log): a plain line every ~10 s
// (ROCKLAB_PROGRESS_SECONDS sets another interval), so a redirected run still shows that it
// lives. `-q` turns both off (enabled = false).
#pragma once

#include <chrono>
#include <functional>
#include <string>

namespace rocklab {

/// One progress line as data: the command's tag, the state, the fraction done (< 0: unknown), the
/// elapsed and the estimated remaining time [s] (< 0: unknown).
struct ProgressEvent {
  std::string tag, what;
  double fraction = -1, elapsed_s = 0, eta_s = -1;
};

/// While it lives, the progress lines of this thread go to `sink` instead of stderr, at the
/// terminal's pace (every 0.5 s after the first second): the Python module's progress callback.
class ProgressSink {
public:
  explicit ProgressSink(std::function<void(const ProgressEvent&)> sink);
  ~ProgressSink();
  ProgressSink(const ProgressSink&) = delete;
  ProgressSink& operator=(const ProgressSink&) = delete;
};

class ProgressLine {
public:
  /// `tag` names the command ("test", "genesis", ...); `terminal` < 0: ask isatty(stderr).
  ProgressLine(std::string tag, bool enabled, int terminal = -1);
  ~ProgressLine();
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  /// Whether a line is due now (terminal: every 0.5 s after the first second; log: every 10 s).
  /// Cheap enough to call every cycle's few hundred steps; false when disabled.
  bool due() const;
  /// Show `what`, led by the elapsed time and, given the fraction done (< 0: unknown), "ETA ..."
  /// from the rate at which the fraction grew since it was first given (or last fell back).
  /// Call when due(), or to force a line.
  void show(const std::string& what, double fraction = -1);
  /// End an in-place terminal line (the next output starts on a fresh line).
  void finish();

  /// The line as shown, without the carriage return: "[rocklab TAG] 1m23s, ETA 45s  WHAT" (no
  /// ETA when eta_s < 0), cut to `width` columns (0: uncut) — exposed for tests.
  std::string format(const std::string& what, double elapsed_s, double eta_s, int width) const;
  /// "7s", "1m23s", "2h05m".
  static std::string duration(double seconds);

private:
  using clock = std::chrono::steady_clock;
  std::string tag_;
  std::function<void(const ProgressEvent&)> sink_; ///< this thread's ProgressSink when made
  bool enabled_;
  bool terminal_;
  double log_every_; ///< [s]
  clock::time_point start_, last_;
  bool shown_ = false;   ///< a line was printed
  bool pending_ = false; ///< a terminal line waits for its newline
  bool have_ref_ = false;
  double ref_fraction_ = 0;    ///< the fraction when its stretch began
  clock::time_point ref_time_; ///< ... and the time
};

} // namespace rocklab
