#include "lab/suite_jobs.hpp"

#include "core/thread_lease.hpp"

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string_view>
#include <thread>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace rocklab {

std::vector<int> share_cores(int cores, std::size_t running) {
  std::vector<int> share(running, 1);
  if (running == 0 || static_cast<std::size_t>(cores) <= running)
    return share;
  const int n = static_cast<int>(running);
  for (int k = 0; k < n; ++k)
    share[static_cast<std::size_t>(k)] = cores / n + (k >= n - cores % n ? 1 : 0);
  return share;
}

// This process's executable as it was started: /proc/self/exe's target, without the " (deleted)"
// the kernel appends once the file is replaced (a rebuild relinks it) or removed.
const std::string& own_executable() {
  static const std::string path = [] {
    std::error_code ec;
    std::string p = std::filesystem::read_symlink("/proc/self/exe", ec).string();
    const std::string_view gone = " (deleted)";
    if (p.size() > gone.size() && p.compare(p.size() - gone.size(), gone.size(), gone) == 0)
      p.resize(p.size() - gone.size());
    return ec ? std::string() : p;
  }();
  return path;
}

namespace {

// The leases of this process's children (src/core/thread_lease.hpp), in start order: the cores
// shared out among the processes that run now, across every run_jobs call of the process (a
// calibration runs several suites at once in threads).
class CoreBroker {
public:
  static CoreBroker& get() {
    static CoreBroker b;
    return b;
  }
  /// A child about to start: its lease file, holding its share of the cores (also in `threads`).
  std::string join(int& threads) {
    std::lock_guard<std::mutex> lock(mu_);
    const std::string file =
        (std::filesystem::temp_directory_path() /
         ("rocklab-lease-" + std::to_string(getpid()) + "-" + std::to_string(serial_++)))
            .string();
    leases_.push_back({file, 0});
    lend_pending_ = false; // the new shares include the cores of any that ended
    share_out();
    threads = leases_.back().threads;
    return file;
  }
  /// A child ended: its cores go to the others once no process has started for a second (a
  /// suite starts its next test within milliseconds; lending the core for that moment would
  /// oversubscribe it while the lent process lets go).
  void leave(const std::string& file) {
    std::lock_guard<std::mutex> lock(mu_);
    std::erase_if(leases_, [&](const Lease& l) { return l.file == file; });
    std::error_code ec;
    std::filesystem::remove(file, ec);
    left_ = std::chrono::steady_clock::now();
    lend_pending_ = true;
  }
  /// Called often by every run_jobs loop: lends the cores of ended children when it is time.
  void tick() {
    std::lock_guard<std::mutex> lock(mu_);
    if (lend_pending_ && std::chrono::steady_clock::now() - left_ > std::chrono::seconds(1)) {
      lend_pending_ = false;
      share_out();
    }
  }

private:
  struct Lease {
    std::string file;
    int threads;
  };
  void share_out() {
    const std::vector<int> share = share_cores(cores_, leases_.size());
    for (std::size_t k = 0; k < leases_.size(); ++k) {
      if (leases_[k].threads == share[k])
        continue;
      leases_[k].threads = share[k];
      const std::string tmp = leases_[k].file + ".new"; // the child never reads half a file
      std::ofstream(tmp) << share[k] << "\n";
      std::error_code ec;
      std::filesystem::rename(tmp, leases_[k].file, ec);
    }
  }
  std::mutex mu_;
  std::vector<Lease> leases_;
  std::chrono::steady_clock::time_point left_;
  bool lend_pending_ = false;
  int cores_ = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  unsigned serial_ = 0;
};

pid_t spawn(const Job& j) {
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, j.log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  std::vector<char*> args;
  for (const std::string& a : j.argv)
    args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  // The child's environment: this one's, with the child's own lease (or none).
  const std::string lease_key = std::string(kThreadLeaseEnv) + "=";
  std::vector<std::string> env_text;
  for (char** e = environ; *e != nullptr; ++e)
    if (std::string_view(*e).substr(0, lease_key.size()) != lease_key)
      env_text.emplace_back(*e);
  if (!j.lease.empty())
    env_text.push_back(lease_key + j.lease);
  std::vector<char*> env;
  for (std::string& e : env_text)
    env.push_back(e.data());
  env.push_back(nullptr);
  pid_t pid = -1;
  // A child that runs this program starts from the file this process runs, which /proc/self/exe
  // keeps even when a rebuild has replaced (or is relinking) the file at its path: a suite once
  // stopped at "cannot start .../rocklab: Permission denied" mid-way through a rebuild.
  const bool self = !own_executable().empty() && j.argv[0] == own_executable();
  const int rc =
      posix_spawn(&pid, self ? "/proc/self/exe" : args[0], &fa, nullptr, args.data(), env.data());
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
      Job& j = jobs[next];
      j.start = std::chrono::steady_clock::now();
      const auto threads_arg = std::find(j.argv.begin(), j.argv.end(), std::string("--threads"));
      if (o.threads == 0 && threads_arg != j.argv.end() && threads_arg + 1 != j.argv.end()) {
        int threads = 1;
        j.lease = CoreBroker::get().join(threads);
        *(threads_arg + 1) = std::to_string(threads);
      }
      try {
        j.pid = spawn(j);
      } catch (...) {
        if (!j.lease.empty())
          CoreBroker::get().leave(j.lease);
        throw;
      }
      live[j.pid] = next;
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
      if (!j.lease.empty())
        CoreBroker::get().leave(j.lease);
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
    CoreBroker::get().tick();
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  if (stopping)
    throw std::runtime_error("interrupted; nothing was written");
}

} // namespace rocklab
