// The Brazilian test's measurement rules, exposed for tests: when the disk split and which load
// is its tensile strength (lab/protocols/brazilian.cpp). Units SI.
#pragma once

#include "lab/crack_monitor.hpp"
#include "lab/frame/loading_frame.hpp"

#include <cstdint>
#include <vector>

namespace rocklab {

/// The step of the crack that completed the diametral split (cracks within 0.2 D of the loaded
/// diameter spanning `fraction` of its ten bins in one run that bridges at most one empty bin),
/// or -1 without a split.
std::int64_t split_crack_step(const std::vector<Crack>& cracks, const SpecimenGeometry& g,
                              double fraction);

/// The reading with the largest load up to step `split` (the peak itself when it came first);
/// load -1 when no reading precedes the split.
LabSample strongest_before(const std::vector<LabSample>& samples, const PeakRecord& peak,
                           std::int64_t split);

} // namespace rocklab
