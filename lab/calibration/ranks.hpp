// Evaluations spread over MPI ranks (`mpirun -np N rocklab calibrate ...`). Every rank runs the
// same, deterministic campaign; the suites an evaluation still needs are shared out by rank, and
// the results meet on the (shared) file system, so N ranks reach exactly the result of one
// process. Without MPI in the build, or when not started by mpirun, there is one rank.
#pragma once

#include <string>

namespace rocklab::calibration {

class Ranks {
public:
  /// Starts MPI when the build has it and mpirun (or another MPI launcher) started this process;
  /// otherwise one rank. One object per process, alive for the whole command.
  Ranks();
  ~Ranks();
  Ranks(const Ranks&) = delete;
  Ranks& operator=(const Ranks&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool root() const { return rank_ == 0; }
  /// True on every rank when `ok` is true on every rank (a collective: every rank must call it).
  bool all(bool ok) const;
  /// The sum over the ranks (a collective).
  double sum(double v) const;
  /// Rank 0's text on every rank (a collective).
  std::string broadcast(const std::string& text) const;
  /// Whether this binary was built with MPI (`rocklab info`).
  static bool available();

private:
  int rank_ = 0, size_ = 1;
  bool started_ = false;
};

} // namespace rocklab::calibration
