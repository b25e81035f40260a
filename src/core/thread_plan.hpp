// The thread plan of the cycle's parallel loops (internal to src/core; Model::plan_threads).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace rocklab::detail {

inline constexpr std::size_t kBlock = 2048; // fixed reduction block: sums do not depend on threads
/// Balls per chunk: the unit in which the thread plan below shares out the balls.
inline constexpr std::size_t kChunk = 256;

/// Who does what in the cycle's parallel loops (Model::plan_threads). Thread t owns the balls
/// [ball[t], ball[t+1]) (whole chunks) in every ball loop, and in the contact loop the contacts
/// whose first end it owns, [contact[t], contact[t+1]) (the list is sorted by first end). So a
/// ball's state is written, read by its contacts and summed by the same thread: data crosses
/// between cores only at the boundary of two threads' balls, and a spatial numbering keeps that
/// boundary a surface. Chunks are shared out by their work (balls plus contacts), not by count.
/// The shares follow the threads' measured speed (a core the host shares runs slower). The plan
/// decides who computes, never what: results do not depend on it.
struct ThreadPlan {
  std::size_t threads = 0, balls = 0, contacts = 0;
  std::uint64_t generation = ~std::uint64_t{0}; ///< the adjacency it was made for
  std::vector<std::size_t> ball, contact;       ///< threads + 1 boundaries each
  /// Reduction blocks (kBlock balls) that two threads share, and each block's place in that list
  /// (-1: one thread's); see plan_block_sum.
  std::vector<std::size_t> shared_blocks;
  std::vector<std::int32_t> shared_slot;
  /// Fraction of the work each thread gets: its measured speed (Model::balance_threads).
  std::vector<double> share;
  /// Since the last look at the speeds: seconds each range spent in the contact loop, the work
  /// it did then (balls + 16 x contacts) and the steps.
  std::vector<double> busy, work;
  std::int64_t steps = 0;
};

} // namespace rocklab::detail
