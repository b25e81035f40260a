// The test machine: runs a protocol (UCS, triaxial, Brazilian, direct tension) on a specimen and
// writes results.json, history.csv, cracks.csv, ParaView files and plots (docs/protocol-format.md).
// Talks to the engine only through the Model's public API and its event stream. Units SI.
#pragma once

#include "lab/crack_monitor.hpp"
#include "lab/protocol.hpp"

#include <atomic>
#include <memory>
#include <nlohmann/json.hpp>
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

/// A recorded point of the test (the measurement channels, SI, compression positive).
struct LabSample {
  std::int64_t step = 0;
  double time = 0;
  double axial_strain = 0;   ///< shortening (compression, Brazilian) or elongation (tension) [-]
  double lateral_strain = 0; ///< compression positive: bulging is negative [-]
  double axial_stress = 0;   ///< platen load / current area; Brazilian: 2F/(pi D t) [Pa]
  double lateral_stress = 0; ///< confining walls [Pa]
  double load = 0;           ///< the quantity whose peak ends the test [Pa]
  double force = 0;          ///< platen (grip) force [N], 2D per unit thickness
};

/// Run one test. On any error nothing is left in OUTDIR. Throws InputError for bad input,
/// PhysicsError for a blow-up.
LabSummary run_lab_test(const Protocol& p, const LabOptions& o);

/// Material behind a protocol: the specimen (from its file, or made by genesis) and its metadata.
struct SpecimenSource {
  std::unique_ptr<Model> model;
  nlohmann::json meta; ///< the specimen file's metadata (material, report, hash, seed)
};
SpecimenSource obtain_specimen(const Protocol& p, const std::atomic<bool>* interrupt = nullptr,
                               bool progress = false);

/// Elastic constants from a loading branch: tangent slope of load vs axial strain over
/// [lo, hi] x peak (pre-peak samples), and -d(lateral)/d(axial) over the same window.
struct ElasticFit {
  double youngs_modulus = 0, poisson_ratio = 0;
  std::size_t points = 0;
};
ElasticFit fit_elastic(const std::vector<LabSample>& s, double peak, double lo, double hi);

} // namespace rocklab
