// Cores lent by a parent process. `rocklab suite` and `rocklab calibrate` run every genesis and
// test as its own process; when fewer of them run than there are cores (the last test of a suite,
// the last seed of an evaluation), the parent lends the idle cores to the ones still running and
// takes them back when a new process starts. It names a file in ROCKLAB_THREAD_LEASE holding the
// thread count (one integer); the cycle looks at it at most five times a second. Results do not
// depend on the thread count (the thread plan's sums are bit-identical at any count), so a lent
// core changes only the wall time.
#pragma once

#include <string_view>

namespace rocklab {

/// The environment variable naming a process's lease file (set by the parent for each child).
inline constexpr std::string_view kThreadLeaseEnv = "ROCKLAB_THREAD_LEASE";

/// Follow the lease, if this process has one: set OpenMP's thread count to the file's value when
/// it changed. Cheap when there is no lease or the last look was under 0.2 s ago.
void follow_thread_lease();

} // namespace rocklab
