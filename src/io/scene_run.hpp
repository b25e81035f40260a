// Running a scene to its stop condition and writing its output directory.
#pragma once

#include "io/scene.hpp"

#include <atomic>
#include <string>

namespace rocklab {

struct RunOptions {
  std::string out_dir;
  bool progress = false;                        ///< print a progress line on stderr
  const std::atomic<bool>* interrupt = nullptr; ///< set by a signal handler to stop the run
};

struct RunSummary {
  std::int64_t steps = 0;
  double time = 0;
  double wall_seconds = 0;
  EventCounts events;
};

/// Run the scene and write OUT/results.json and OUT/history.csv. On any error nothing is left
/// half-written in OUT (a directory that did not exist is removed again).
RunSummary run_scene(Scene& scene, const RunOptions& opts);

} // namespace rocklab
