// Deterministic parallel loops of the engine (internal to src/core): fixed-block reductions whose
// result does not depend on the thread count, and the size below which a loop runs serially.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <omp.h>
#include <vector>

#include "core/thread_plan.hpp"

namespace rocklab::detail {

// Loops shorter than this run on the calling thread: forking costs more than it saves, and on a
// busy machine a barrier can cost a whole scheduler time slice. Results do not depend on it.
inline constexpr std::size_t kParallelMin = 1024;

/// Sum K quantities over n items in fixed blocks, so the result is bit-identical at any thread
/// count. f(i, acc) adds item i's contributions into acc[0..K).
template <int K, class F> std::array<double, K> block_sum(std::size_t n, F&& f) {
  const std::size_t nblocks = (n + kBlock - 1) / kBlock;
  std::array<double, K> total{};
  if (nblocks == 0)
    return total;
  // Small stack buffer for the common case; larger models use a heap buffer once per call.
  constexpr std::size_t kStack = 256;
  std::array<std::array<double, K>, kStack> stack_parts;
  std::vector<std::array<double, K>> heap_parts;
  std::array<double, K>* parts = stack_parts.data();
  if (nblocks > kStack) {
    heap_parts.resize(nblocks);
    parts = heap_parts.data();
  }
#pragma omp parallel for schedule(static) if (n >= kParallelMin)
  for (std::size_t b = 0; b < nblocks; ++b) {
    std::array<double, K> acc{};
    const std::size_t end = std::min(n, (b + 1) * kBlock);
    for (std::size_t i = b * kBlock; i < end; ++i)
      f(i, acc);
    parts[b] = acc;
  }
  for (std::size_t b = 0; b < nblocks; ++b)
    for (int k = 0; k < K; ++k)
      total[k] += parts[b][k];
  return total;
}

/// Run f(t, begin, end) for every thread range of `bounds` (threads + 1 boundaries) in a parallel
/// region (serially below kParallelMin items, or when the region has fewer threads than ranges).
template <class F> void for_ranges(const std::vector<std::size_t>& bounds, F&& f) {
  const std::size_t ranges = bounds.size() - 1;
  const bool parallel = bounds.back() - bounds.front() >= kParallelMin && ranges > 1;
#pragma omp parallel if (parallel)
  {
    const std::size_t tid = static_cast<std::size_t>(omp_get_thread_num());
    const std::size_t nt = static_cast<std::size_t>(omp_get_num_threads());
    for (std::size_t t = tid; t < ranges; t += nt)
      f(t, bounds[t], bounds[t + 1]);
  }
}

/// The same sum as block_sum<K>(plan.ball.back(), ...) to the bit, over the balls of a thread
/// plan: every ball is handled by the thread that owns it. f(i) does ball i's work and returns its
/// record; add(acc, record) adds it (in the order block_sum's f would have). A block of kBlock
/// balls inside one thread's range is summed as it goes; a block that two threads share keeps its
/// balls' records in `spill` and is summed after the loop, in ball order.
template <int K, class Rec, class F, class Add>
std::array<double, K> plan_block_sum(const ThreadPlan& plan, std::vector<Rec>& spill,
                                     std::vector<std::array<double, K>>& parts, F&& f, Add&& add) {
  const std::size_t n = plan.ball.back();
  const std::size_t nblocks = (n + kBlock - 1) / kBlock;
  parts.resize(nblocks);
  spill.resize(plan.shared_blocks.size() * kBlock);
  for_ranges(plan.ball, [&](std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t i0 = begin; i0 < end;) {
      const std::size_t blk = i0 / kBlock, start = blk * kBlock;
      const std::size_t stop = std::min(end, start + kBlock);
      if (plan.shared_slot[blk] < 0) { // the whole block is this thread's
        std::array<double, K> acc{};
        for (std::size_t i = i0; i < stop; ++i)
          add(acc, f(i));
        parts[blk] = acc;
      } else {
        Rec* out = spill.data() + static_cast<std::size_t>(plan.shared_slot[blk]) * kBlock;
        for (std::size_t i = i0; i < stop; ++i)
          out[i - start] = f(i);
      }
      i0 = stop;
    }
  });
  for (std::size_t k = 0; k < plan.shared_blocks.size(); ++k) {
    const std::size_t blk = plan.shared_blocks[k], start = blk * kBlock;
    std::array<double, K> acc{};
    for (std::size_t i = start; i < std::min(n, start + kBlock); ++i)
      add(acc, spill[k * kBlock + (i - start)]);
    parts[blk] = acc;
  }
  std::array<double, K> total{};
  for (const auto& part : parts)
    for (int k = 0; k < K; ++k)
      total[k] += part[k];
  return total;
}

inline double sign(double v) {
  return v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0);
}

} // namespace rocklab::detail
