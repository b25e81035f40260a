// A laboratory test in the loading frame (UCS, triaxial, Brazilian, direct tension, ...): its own
// protocol keys, the fixtures it mounts, what its readings mean, when it ends, what it reports,
// prints and plots, and which material properties it gives suites and calibrations. One file per
// test under lab/protocols/, one row in lab/protocol_table.cpp; the frame (lab/frame/) and the
// run loop (lab/frame_run.cpp) do the rest. The interface lives with the frame that calls it, so
// the tests depend on the frame and not the other way round. Units SI.
#pragma once

#include "io/results.hpp"
#include "lab/frame/loading_frame.hpp"
#include "lab/lab_protocol.hpp"
#include "lab/property.hpp"
#include "viz/svg_plots.hpp"

#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace rocklab {

class JsonObject;

/// How a test's stress-strain plot and crack map are drawn.
struct PlotLabels {
  std::string x, y;     ///< axis labels
  bool lateral = false; ///< also plot the axial stress against the lateral strain
  int map_axis = 1;     ///< the crack map's section normal (0 x, 1 y, 2 z)
  std::string curve = "axial stress vs axial strain"; ///< the load curve's legend
};

/// What a suite gathers from its tests' results: values by name (set by the first test of the
/// kind that measures them) and series by name, one entry per test that adds to them (the
/// compression tests' confinements and peaks, from which the triaxial fits the envelope).
struct SuiteValues {
  std::map<std::string, double> values;
  std::map<std::string, std::vector<double>> series;
  /// The value, NaN when no test gave it.
  double get(const std::string& name) const;
  bool has(const std::string& name) const { return !std::isnan(get(name)); }
};

class FrameTest : public LabProtocol {
public:
  /// Runs the protocol file in the frame (lab/frame_run.cpp).
  LabSummary run(const nlohmann::json& j, const std::string& file, const LabOptions& o) override;
  void print(const LabSummary& s, const std::string& out_dir) const override;

  /// Reads the test's own keys of the protocol's "loading" and "stop" sections into the test
  /// (`p`: the keys every test shares, already read). Default: none. A key another test reads is
  /// refused naming that test (lab/protocol.cpp).
  virtual void read_options(JsonObject& /*loading*/, JsonObject& /*stop*/, const Protocol& /*p*/) {}
  /// How the frame is set up for this test, with the options read.
  virtual FrameSetup setup() const = 0;
  /// What carries the load (default: flat platens with the protocol's loading.platen_friction).
  virtual std::unique_ptr<Actuator> actuator(const Protocol& p) const;
  /// The confining walls of a confined test (default: none).
  virtual std::unique_ptr<ConfiningWalls> confinement() const { return nullptr; }
  /// The specimen's shape from its genesis record ("" without one): by default not a disk.
  virtual void check_shape(const std::string& shape, const Protocol& p) const;
  /// The specimen's shape as its genesis recorded it (the report's `specimen`; null without a
  /// record), given before loading (default: not read).
  virtual void read_specimen(const nlohmann::json& /*shape*/) {}
  /// The axial strain of the current reading (called while loading) [-].
  virtual double axial_strain(const LoadingFrame& f) const = 0;
  /// Axial stress and load of a reading whose force and lateral channels are read [Pa].
  virtual void stresses(const LoadingFrame& f, LabSample& s) const = 0;
  /// Called with each fine reading of the loading (every history_every / 10 steps).
  virtual void sampled(const LoadingFrame& /*f*/, const LabSample& /*s*/) {}
  /// Called at stop checks once the load fell below stop.post_peak_fraction of its peak: the stop
  /// reason, or "" to go on (default: stop).
  virtual std::string stop_after_drop(LoadingFrame& f);
  /// Called at stop checks while loading, past stop.min_steps, before any drop: a stop reason, or
  /// "" to go on (default: go on).
  virtual std::string stop_while_loading(LoadingFrame& /*f*/) { return ""; }
  /// The test's own results (the frame writes the common ones).
  virtual void results(const LoadingFrame& f, nlohmann::json& r) const = 0;
  virtual PlotLabels plot_labels() const = 0;
  /// The test's own lines of the printout, after the first (test, material, grains, steps) and
  /// before the crack counts (default: none).
  virtual void print_results(const nlohmann::json& /*r*/) const {}
  /// The test's own markers on the stress-strain plot (`samples`: the run's fine readings;
  /// default: none).
  virtual void plot_markers(const std::vector<LabSample>& /*samples*/, const nlohmann::json& /*r*/,
                            std::vector<PlotMarker>& /*m*/) const {}
  /// The material properties this test gives suites and calibrations, each with how it is shown
  /// and used (lab/property.hpp; default: none).
  virtual std::vector<SuiteProperty> suite_properties() const { return {}; }
  /// The keys of this test's results.json a suite shows per test (tests.csv, the suite's table
  /// and summary.json's test rows; only name, label and kind are read; default: none).
  virtual std::vector<SuiteProperty> result_columns() const { return {}; }
  /// Add this test's results.json to a suite's values (default: nothing).
  virtual void add_to_suite(const nlohmann::json& /*r*/, SuiteValues& /*v*/) const {}
  /// This test's part of a suite's material properties (summary.json), from what every test
  /// gathered: by default each declared property's value (null when none was measured).
  virtual void suite_results(const SuiteValues& v, nlohmann::json& props) const;
  /// The test's own state, for checkpoints.
  virtual void save(nlohmann::json& /*state*/) const {}
  virtual void load(const nlohmann::json& /*state*/, const std::string& /*file*/) {}
};

/// The stop reason of the standard post-peak rule.
std::string load_fell_reason(const Protocol& p);

} // namespace rocklab
