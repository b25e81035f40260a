// The per-seed results of a calibration (docs/calibration.md, "Per-seed results"): one CSV row per
// replicate, its identity (the hash of the card, the tests with their seed, the rocklab version
// and the tests' measurement revisions: the evaluations' cache key), its seed and every property
// its suite measured. A later run, here or on another machine, merges the rows instead of running
// those replicates again, so a campaign or a validation longer than one sitting accumulates.
// Units SI, as in summary.json.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <map>
#include <string>

namespace rocklab::calibration {

class SeedRows {
public:
  SeedRows() = default;
  /// The rows of `path`, an empty table if the file does not exist; InputError (exit status 2)
  /// naming the file and line for a malformed row.
  explicit SeedRows(std::string path);
  const std::string& path() const { return path_; }
  /// A replicate's properties (null where it measured none), or nullptr when it has no row.
  const nlohmann::json* find(const std::string& key) const;
  /// Adds (or replaces) a replicate's row; the file is rewritten at once (written beside it, then
  /// renamed), so a run killed later keeps every row that finished.
  void add(const std::string& key, std::uint64_t seed, const nlohmann::json& properties);
  std::size_t size() const { return rows_.size(); }
  /// The table as CSV: key, seed, then every property any row has, in name order (empty: not
  /// measured); rows in key order.
  std::string csv() const;

private:
  struct Row {
    std::uint64_t seed = 0;
    nlohmann::json properties = nlohmann::json::object();
  };
  std::string path_;
  std::map<std::string, Row> rows_;
};

} // namespace rocklab::calibration
