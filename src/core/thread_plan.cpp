// The thread plan of the cycle (thread_plan.hpp): which balls and contacts each thread owns, and
// how the shares follow the threads' measured speed. Nothing here changes a result.
#include "core/model.hpp"

#include "core/parallel.hpp"

#include <algorithm>
#include <cmath>
#include <omp.h>

namespace rocklab {

using namespace detail;

namespace {

// Work of a ball range: a contact update costs about as much as this many ball updates.
constexpr std::size_t kContactWork = 16;
// Steps between two looks at the threads' speeds, and the change of share worth a new plan.
constexpr std::int64_t kBalanceSteps = 32;
constexpr double kShareStep = 0.01;

} // namespace

const ThreadPlan& Model::plan_threads() {
  const std::size_t T = static_cast<std::size_t>(std::max(1, omp_get_max_threads()));
  const std::size_t n = balls.size(), nc = contacts_.size();
  ThreadPlan& p = plan_;
  if (p.threads == T && p.balls == n && p.contacts == nc && p.generation == adjacency_generation_)
    return p;
  if (p.share.size() != T)
    p.share.assign(T, 1.0 / static_cast<double>(T));
  p.busy.assign(T, 0.0);
  p.work.assign(T, 0.0);
  p.steps = 0;
  p.threads = T;
  p.balls = n;
  p.contacts = nc;
  p.generation = adjacency_generation_;
  p.ball.assign(T + 1, n);
  p.contact.assign(T + 1, nc);
  p.ball[0] = p.contact[0] = 0;
  // The first contact whose first end is ball i or later (the list is sorted by first end).
  auto first_contact = [&](std::size_t i) {
    const auto it = std::partition_point(contacts_.begin(), contacts_.end(), [&](const Contact& c) {
      return static_cast<std::size_t>(c.end1) < i;
    });
    return static_cast<std::size_t>(it - contacts_.begin());
  };
  auto work = [&](std::size_t i) {
    return static_cast<double>(i + kContactWork * first_contact(i));
  };
  const double total = work(n);
  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  std::size_t chunk = 0;
  double target = 0;
  for (std::size_t t = 1; t < T; ++t) {
    target += p.share[t - 1] * total;
    while (chunk < chunks && work(std::min(n, chunk * kChunk)) < target)
      ++chunk;
    p.ball[t] = std::max(p.ball[t - 1], std::min(n, chunk * kChunk));
    p.contact[t] = first_contact(p.ball[t]);
  }
  p.shared_blocks.clear();
  p.shared_slot.assign((n + kBlock - 1) / kBlock, -1);
  for (std::size_t t = 1; t < T; ++t) {
    const std::size_t blk = p.ball[t] / kBlock;
    if (p.ball[t] % kBlock != 0 && p.ball[t] < n && p.shared_slot[blk] < 0) {
      p.shared_slot[blk] = static_cast<std::int32_t>(p.shared_blocks.size());
      p.shared_blocks.push_back(blk);
    }
  }
  return p;
}

void Model::time_range(std::size_t t, double seconds) {
  ThreadPlan& p = plan_;
  p.busy[t] += seconds;
  p.work[t] += static_cast<double>((p.ball[t + 1] - p.ball[t]) +
                                   kContactWork * (p.contact[t + 1] - p.contact[t]));
}

void Model::balance_threads() {
  // Each thread's speed is the work it did over the time it took in the contact loop. A core
  // that the host shares with other work runs slower (on the 2-core KVM guests here one of two
  // busy cores ran 40 % slower at times): its share shrinks, so neither waits at the barrier.
  ThreadPlan& p = plan_;
  if (p.threads < 2 || ++p.steps < kBalanceSteps)
    return;
  std::vector<double> speed(p.threads, 0.0);
  double sum = 0;
  for (std::size_t t = 0; t < p.threads; ++t) {
    if (!(p.busy[t] > 0) || !(p.work[t] > 0)) { // not measured (a serial loop): keep the shares
      std::fill(p.busy.begin(), p.busy.end(), 0.0);
      std::fill(p.work.begin(), p.work.end(), 0.0);
      p.steps = 0;
      return;
    }
    speed[t] = p.work[t] / p.busy[t];
    sum += speed[t];
  }
  double change = 0;
  for (std::size_t t = 0; t < p.threads; ++t) {
    const double share = 0.5 * p.share[t] + 0.5 * speed[t] / sum; // smoothed against noise
    change = std::max(change, std::abs(share - p.share[t]));
    p.share[t] = share;
  }
  std::fill(p.busy.begin(), p.busy.end(), 0.0);
  std::fill(p.work.begin(), p.work.end(), 0.0);
  p.steps = 0;
  if (change > kShareStep)
    p.generation = ~std::uint64_t{0}; // a new plan at the next loop
}

void Model::set_thread_shares(const std::vector<double>& shares) {
  double sum = 0;
  for (double s : shares) {
    if (!(s > 0) || !std::isfinite(s))
      throw std::invalid_argument("set_thread_shares: every share must be positive");
    sum += s;
  }
  plan_.share = shares;
  for (double& s : plan_.share)
    s /= sum;
  plan_.generation = ~std::uint64_t{0};
}

} // namespace rocklab
