// A calibration file (docs/calibration.md): the base material card, the targets with their
// tolerances, the free micro-parameters with their roles and bounds, the tests that measure the
// targets, the replicate seeds and the budget; and how a parameter vector becomes a card. Units SI.
#pragma once

#include "lab/calibration/stages.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace rocklab::calibration {

/// A free parameter bound to the card: a number or a {"mean", "sd"} strength at `path`
/// ("section.key"), or, for a ratio "A/B", the value of A over the value of B (B set first).
struct CardParam {
  std::string
      key; ///< as written in the file: "flatjoint.fj_ten" or "flatjoint.fj_coh/flatjoint.fj_ten"
  std::string path; ///< the card value it sets (A for a ratio)
  std::string over; ///< B for a ratio, else empty
  Param param;      ///< role, bounds, start (the card's value)
};

struct CalibrationFile {
  std::string file, name, material_file;
  nlohmann::json material; ///< the base card as read
  std::vector<Target> targets;
  std::vector<CardParam> params;
  nlohmann::json tests = nlohmann::json::array(); ///< suite tests (docs/protocol-format.md)
  std::vector<std::uint64_t> seeds;               ///< replicate specimens per evaluation
  /// Per-seed results read before and written after each replicate ("" : OUTDIR/seeds.csv)
  std::string seeds_file;
  Budget budget;
};

/// Reads and checks a calibration file; InputError (exit status 2) names the file, the key, the
/// value and what is allowed.
CalibrationFile load_calibration(const std::string& path);

/// The base card with the parameters set to `values` (in the order of `params`): a distribution
/// keeps its coefficient of variation.
nlohmann::json apply_params(const nlohmann::json& card, const std::vector<CardParam>& params,
                            const std::vector<double>& values);

/// The targets a calibration understands and the suite tests each needs.
struct TargetNeed {
  const char* property;
  const char* test;  ///< the test type that measures it
  int count = 1;     ///< how many tests of that type at least
  const char* other; ///< a second test type it needs as well, or nullptr
};
const std::vector<TargetNeed>& target_needs();

/// A card with `overrides` ("section.key" -> value) set the way a calibration sets its
/// parameters: a number on a {"mean", "sd"} strength keeps its coefficient of variation, a slit or
/// gapped fraction takes its share from the bonded one, anything else replaces the value. A key
/// whose section the card lacks is an InputError naming `where` and the key; the card's own
/// checks judge the values when it is loaded.
nlohmann::json override_card(const nlohmann::json& card,
                             const std::vector<std::pair<std::string, nlohmann::json>>& overrides,
                             const std::string& where);

} // namespace rocklab::calibration
