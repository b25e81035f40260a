// Result files of a run: results.json (final state) and history.csv rows. Units are SI.
#pragma once

#include "core/model.hpp"
#include "io/scene.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <iosfwd>

namespace rocklab {

/// Final state: balls, walls, contacts (global and contact-plane force and moment), energies.
nlohmann::json results_json(const Model& m, const EventCounts& counts,
                            const std::string& scene_file);

/// Contacts listed in results.json by default (ContactOutputMode::Auto, scene.hpp).
inline constexpr std::size_t kContactsAutoLimit = 20000;
bool contacts_written(ContactOutputMode mode, std::size_t contacts);

/// results.json written as a stream (the ball and contact lists one item at a time, never the
/// whole document in memory); the text of results_json(...).dump(1) plus `contact_count` and,
/// when the list is left out, `contacts_omitted` saying why.
void write_results_json(std::ostream& os, const Model& m, const EventCounts& counts,
                        const std::string& scene_file, ContactOutputMode mode);

/// Energies as a JSON object (joules).
nlohmann::json energy_json(const EnergyLedger& e);

std::string history_header(const std::vector<HistoryColumn>& cols);
std::string history_row(const Model& m, const std::vector<HistoryColumn>& cols,
                        const EventCounts& counts);

/// Shortest text that reads back to the same double.
std::string format_double(double v);

/// A number of a results object, or `fallback` where the key is missing or not a number (a
/// measurement that could not be made is written as null).
inline double json_number(const nlohmann::json& r, const char* key, double fallback) {
  const auto it = r.find(key);
  return it != r.end() && it->is_number() ? it->get<double>() : fallback;
}

/// A finite value as a JSON number, anything else as null (a measurement that could not be made).
inline nlohmann::json number_or_null(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

} // namespace rocklab
