// One kind of laboratory test: it reads and runs its protocol files. lab/protocol_table.cpp lists
// every kind by the name a protocol file gives in "test"; `rocklab test` looks the kind up there.
// Units SI.
#pragma once

#include <nlohmann/json.hpp>

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

namespace rocklab {

struct LabOptions {
  std::string out_dir;
  bool progress = false;                        ///< progress lines on stderr
  const std::atomic<bool>* interrupt = nullptr; ///< set by a signal handler
  std::int64_t checkpoint_every = 0;            ///< > 0: write a checkpoint every this many steps
  std::string checkpoint_path;                  ///< default: OUTDIR.checkpoint
  std::string resume_path;                      ///< continue from this checkpoint
};

struct LabSummary {
  nlohmann::json results;         ///< what results.json holds
  std::vector<std::string> files; ///< files written, relative to the output directory
  double wall_seconds = 0;
  bool interrupted = false; ///< stopped by a signal (a checkpoint was written if enabled)
};

class LabProtocol {
public:
  virtual ~LabProtocol() = default;
  /// The protocol's "test" name.
  virtual const char* name() const = 0;
  /// Run a protocol file of this kind (`j` is its JSON). On any error nothing is left in
  /// OUTDIR. Throws InputError for bad input, PhysicsError for a blow-up.
  virtual LabSummary run(const nlohmann::json& j, const std::string& file, const LabOptions& o) = 0;
  /// The revision of what this test measures: raised when the same inputs give different results
  /// (a changed measurement rule), so that cached calibration evaluations of it run again.
  virtual int revision() const { return 1; }
  /// The summary `rocklab test` prints on stdout.
  virtual void print(const LabSummary& s, const std::string& out_dir) const = 0;
};

} // namespace rocklab
