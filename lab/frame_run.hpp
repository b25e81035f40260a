// Running a test in the loading frame: the specimen (from its file, or made by genesis), the step
// loop with checkpoints and progress, the ParaView snapshots, and the result files (results.json,
// history.csv, cracks.csv, stress_strain.svg, crack_map.svg). Units SI.
#pragma once

#include "lab/lab_protocol.hpp"
#include "lab/protocol.hpp"

#include <atomic>
#include <memory>

namespace rocklab {

class FrameTest;
class Model;

/// Run one test in the frame. On any error nothing is left in OUTDIR. Throws InputError for bad
/// input, PhysicsError for a blow-up.
LabSummary run_frame_test(FrameTest& test, const Protocol& p, const LabOptions& o);
/// The same for a protocol read by load_protocol (its test, holding the options it read).
LabSummary run_lab_test(const Protocol& p, const LabOptions& o);

/// Material behind a protocol: the specimen (from its file, or made by genesis) and its metadata.
struct SpecimenSource {
  std::unique_ptr<Model> model;
  nlohmann::json meta; ///< the specimen file's metadata (material, report, hash, seed)
};
SpecimenSource obtain_specimen(const Protocol& p, const std::atomic<bool>* interrupt = nullptr,
                               bool progress = false);

} // namespace rocklab
