// Deterministic parallel loops of the engine (internal to src/core): fixed-block reductions whose
// result does not depend on the thread count, and the size below which a loop runs serially.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <vector>

namespace rocklab::detail {

inline constexpr std::size_t kBlock = 2048; // fixed reduction block: sums do not depend on threads
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

inline double sign(double v) {
  return v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0);
}

} // namespace rocklab::detail
