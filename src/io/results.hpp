// Result files of a run: results.json (final state) and history.csv rows. Units are SI.
#pragma once

#include "core/model.hpp"
#include "io/scene.hpp"

#include <nlohmann/json.hpp>

namespace rocklab {

/// Final state: balls, walls, contacts (global and contact-plane force and moment), energies.
nlohmann::json results_json(const Model& m, const EventCounts& counts,
                            const std::string& scene_file);

/// Energies as a JSON object (joules).
nlohmann::json energy_json(const EnergyLedger& e);

std::string history_header(const std::vector<HistoryColumn>& cols);
std::string history_row(const Model& m, const std::vector<HistoryColumn>& cols,
                        const EventCounts& counts);

/// Shortest text that reads back to the same double.
std::string format_double(double v);

} // namespace rocklab
