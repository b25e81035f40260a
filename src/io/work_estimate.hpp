// What a run will cost, estimated before it starts: the grain-steps it asks for, the memory its
// records need and the wall time that takes. Printed at set-up; past an hour a warning; past the
// machine's memory a refusal (InputError, exit 2) naming the file and the key that asks for it.
// Used by the scene runner and the drop test (genesis has its own estimate of the grains a card
// packs, materials/genesis/estimate.cpp, and uses physical_memory from here).
#pragma once

#include <string>

namespace rocklab {

struct WorkEstimate {
  double steps = 0;        ///< time steps, all stages or runs together
  double ball_steps = 0;   ///< grains x steps
  double bytes = 0;        ///< memory the records (history rows) will need [bytes]
  bool open_ended = false; ///< a stage ends on a condition and has no step cap (not counted)
};

/// A number for a message: `digits` significant digits, as iostream prints them (1e+09, 0.5).
std::string message_number(double v, int digits);

/// The machine's physical memory [bytes] (0 when unknown).
double physical_memory();

/// The wall time of `e` on `threads` threads [s]: a rough figure from the cycle's measured cost
/// per grain-step and per step (docs/performance.md), within a factor of about three for the
/// shipped contact models.
double estimated_seconds(const WorkEstimate& e, int threads);

/// Prints the estimate on stdout (unless quiet) and a warning on stderr when it passes an hour;
/// throws InputError naming `file` and `key` when the records need more than 80 % of the
/// machine's memory.
void check_estimate(const WorkEstimate& e, const std::string& file, const std::string& key,
                    bool quiet);

/// During a run: warns on stderr when the pace measured so far (`fraction` of the work done in
/// `wall` seconds) projects past an hour — work the set-up estimate could not see (a time step
/// that shrank once contacts formed).
void warn_projection(const std::string& file, double fraction, double wall);

} // namespace rocklab
