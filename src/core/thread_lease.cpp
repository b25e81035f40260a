#include "core/thread_lease.hpp"

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <omp.h>

#include <string>

namespace rocklab {

namespace {

// The thread count a lease file holds, or 0 when it cannot be read or is out of [1, 1024].
int read_thread_lease(const char* path) {
  std::FILE* f = std::fopen(path, "r");
  if (!f)
    return 0;
  int n = 0;
  if (std::fscanf(f, "%d", &n) != 1 || n < 1 || n > 1024)
    n = 0;
  std::fclose(f);
  return n;
}

} // namespace

void follow_thread_lease() {
  static const char* const path = std::getenv(std::string(kThreadLeaseEnv).c_str());
  if (path == nullptr || *path == '\0')
    return;
  using clock = std::chrono::steady_clock;
  static std::atomic<clock::rep> next{0};
  const clock::rep now = clock::now().time_since_epoch().count();
  clock::rep due = next.load(std::memory_order_relaxed);
  if (now < due)
    return;
  // One caller looks (several models may cycle in threads of one process, e.g. tests).
  const clock::rep later =
      now + std::chrono::duration_cast<clock::duration>(std::chrono::milliseconds(200)).count();
  if (!next.compare_exchange_strong(due, later))
    return;
  const int n = read_thread_lease(path);
  if (n > 0 && n != omp_get_max_threads())
    omp_set_num_threads(n);
}

} // namespace rocklab
