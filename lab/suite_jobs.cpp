#include "lab/suite_jobs.hpp"

#include <csignal>
#include <cstdio>
#include <cstring>
#include <map>
#include <stdexcept>
#include <thread>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace rocklab {

namespace {

pid_t spawn(const Job& j) {
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, j.log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  std::vector<char*> args;
  for (const std::string& a : j.argv)
    args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, args[0], &fa, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0)
    throw std::runtime_error("cannot start " + j.argv[0] + ": " + std::strerror(rc));
  return pid;
}

} // namespace

void run_jobs(std::vector<Job>& jobs, int parallel, const SuiteOptions& o) {
  std::size_t next = 0, running = 0;
  std::map<pid_t, std::size_t> live;
  bool stopping = false;
  auto stop = [&] { // no new jobs; the running ones get SIGINT (they finish as interrupted)
    if (stopping)
      return;
    stopping = true;
    for (const auto& [p, k] : live)
      kill(p, SIGINT);
  };
  while (next < jobs.size() || running > 0) {
    while (!stopping && running < static_cast<std::size_t>(parallel) && next < jobs.size()) {
      jobs[next].start = std::chrono::steady_clock::now();
      jobs[next].pid = spawn(jobs[next]);
      live[jobs[next].pid] = next;
      ++running;
      ++next;
    }
    if (running == 0)
      break;
    // Only this call's own children are reaped (several suites may run at once in threads).
    int st = 0;
    pid_t pid = 0;
    for (const auto& [p, k] : live)
      if ((pid = waitpid(p, &st, WNOHANG)) > 0)
        break;
    if (pid > 0) {
      Job& j = jobs[live[pid]];
      live.erase(pid);
      --running;
      j.status = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
      j.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - j.start).count();
      if (o.progress)
        std::fprintf(stderr, "[rocklab suite] %s %s in %.1f s\n", j.label.c_str(),
                     j.status == 0 ? "finished" : "FAILED", j.seconds);
      // A child that was interrupted (status 130) or stopped from outside (SIGINT, SIGTERM,
      // SIGHUP, SIGKILL) did not fail on its input: the signal reached it before this process
      // (kill -- -PGID, a batch system), and the suite stops as interrupted instead of recording
      // a failed test (which a calibration would cache). A crash stays a failed test.
      const int sig = WIFSIGNALED(st) ? WTERMSIG(st) : 0;
      if (j.status == 130 || sig == SIGINT || sig == SIGTERM || sig == SIGHUP || sig == SIGKILL)
        stop();
      continue;
    }
    if (o.interrupt && o.interrupt->load())
      stop();
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  if (stopping)
    throw std::runtime_error("interrupted; nothing was written");
}

} // namespace rocklab
