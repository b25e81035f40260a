// Protocol files of tests in the loading frame: what test to run on which specimen, how fast, when
// to stop and what to write (docs/protocol-format.md). These are the keys every test shares; a
// test reads its own keys (confinement, grips, jaws, split rule, ...) into itself
// (FrameTest::read_options, lab/protocols/). All quantities SI.
#pragma once

#include "materials/material_card.hpp"

#include <nlohmann/json.hpp>

#include <memory>
#include <optional>
#include <string>

namespace rocklab {

class FrameTest;

/// Default loading rate: the quasi-static rate of docs/results.md (strain rate, 1/s).
inline constexpr double kDefaultStrainRate = 1.0;

struct Protocol {
  std::string file; ///< the protocol file (paths inside it are relative to its folder)
  std::string name;
  std::string test = "ucs"; ///< the test's name in lab/protocol_table.cpp
  /// The test, holding its own options as the file gave them (it runs the protocol).
  std::shared_ptr<FrameTest> frame_test;
  // specimen: a specimen file, or a material card run through genesis first
  std::string specimen_file;
  std::string material_file;
  nlohmann::json shape;              ///< replaces the card's specimen shape for genesis (or null)
  nlohmann::json cut;                ///< replaces the card's cut (test shape cut from the block)
  std::optional<std::uint64_t> seed; ///< replaces the card's seed for genesis
  // loading
  double strain_rate = kDefaultStrainRate; ///< total rate: both platens together [1/s]
  double platen_velocity = 0;              ///< > 0: speed of each platen (or grip) [m/s]
  std::int64_t ramp_steps = 2000;          ///< the platen speed rises smoothly over this many steps
  double seating_stress = 1e5;             ///< platens first close to this axial stress [Pa]
  /// Below this axial stress the loading runs at approach_rate times its rate, then slows to it
  /// over ramp_steps (0: no approach) [Pa].
  double approach_stress = 0;
  double approach_rate = 3; ///< the approach's rate as a multiple of the loading rate [-]
  /// `loading.platen_friction`, the platens' ball-facet friction coefficient (0 lubricated, steel
  /// on rock unlubricated about 0.2-0.5); not given: the test's own (FrameTest::actuator: UCS,
  /// triaxial lubricated; Brazilian the specimen's wall rule).
  std::optional<double> platen_friction;
  /// > 0: density scaling from the start of loading, the time step raised to this quantile of
  /// the grains' own stable steps (Model::scale_density); 0: off.
  double density_scaling = 0;
  /// > 0: the factor on the automatic time step from the start of loading (replaces the
  /// specimen's, Settings::timestep_safety); 0: the specimen's.
  double timestep_safety = 0;
  // stop
  double post_peak_fraction = 0.9; ///< stop when the load falls to this fraction of its peak
  std::int64_t min_steps = 1000;   ///< ... but not before this many loading steps
  double strain_limit = 0;         ///< > 0: also stop at this axial strain [-]
  std::int64_t max_steps = 5'000'000;
  // output
  std::int64_t history_every = 100; ///< a history row every this many steps
  double vtk_every_strain = 5e-4;   ///< a VTK snapshot every this much axial strain (0: none)
  bool vtk = true;                  ///< write ParaView files
  bool plots = true;                ///< write the SVG stress-strain plot and crack map
  bool orientation = false;         ///< track grain rotation from the loading on (ParaView)
  bool cells = true;                ///< ParaView: the grains' power cells and crack faces
  double event_window = 0;    ///< how long a crack keeps its event open [s]; 0: Hazzard & Young's
  bool moment_tensors = true; ///< follow the events' moment tensors (lab/ae_monitor)
  nlohmann::json raw;         ///< the file as read
  std::string text_hash;      ///< hash of the file's text
};

/// Read and validate a protocol file of a test in the loading frame; errors name the file, key,
/// value and allowed range.
/// `test`: as for protocol_from_json.
Protocol load_protocol(const std::string& path, std::shared_ptr<FrameTest> test = nullptr);
/// Read a protocol from JSON (suites embed them); `file` locates relative paths and errors.
/// `test`: the test object that reads the protocol's options and runs it (one of the protocol's
/// "test" kind; null: made here).
Protocol protocol_from_json(const nlohmann::json& j, const std::string& file,
                            const std::string& key_path, std::shared_ptr<FrameTest> test = nullptr);

/// A path written in an input file, relative to that file's folder (absolute paths stay).
std::string resolve(const std::string& file, const std::string& p);

} // namespace rocklab
