// The processes of a suite: each genesis and each test runs as its own `rocklab` process (a
// failed or killed test cannot take the others down), at most `parallel` at once.
#pragma once

#include "lab/suite.hpp"

#include <chrono>
#include <string>
#include <sys/types.h>
#include <vector>

namespace rocklab {

struct Job {
  std::string label;
  std::vector<std::string> argv;
  std::string log;
  std::string lease; ///< the file of its lent cores (ROCKLAB_THREAD_LEASE), "" when fixed
  pid_t pid = -1;
  int status = -1;
  double seconds = 0;
  std::chrono::steady_clock::time_point start;
};

/// Run the jobs, at most `parallel` at once; fills each job's status and seconds. With
/// `o.threads` 0 a job's `--threads` argument is its share of the cores among all the processes
/// this process runs now, and the share follows as others start and end
/// (src/core/thread_lease.hpp); otherwise it stays as given. On interrupt
/// the children (which got the same signal from the terminal, or get SIGINT from here) are waited
/// for and the suite fails; so it does when a child exits with 130 or dies by a signal (the
/// signal reached it first).
void run_jobs(std::vector<Job>& jobs, int parallel, const SuiteOptions& o);

/// `cores` shared out among `running` processes in start order: equal shares, the remainder to
/// the latest started (the earlier ones are nearer their end), at least one each.
std::vector<int> share_cores(int cores, std::size_t running);

} // namespace rocklab
