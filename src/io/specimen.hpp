// Specimen and checkpoint files: a versioned file that restores a Model exactly, so a run
// continued from it is bit-identical to one that never stopped.
//
// Layout: one line of JSON (the header: format, version, counts, and any metadata the caller
// adds), then a binary body written field by field in little-endian order (no struct padding, so
// the same model always gives the same bytes).
#pragma once

#include "core/model.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace rocklab {

/// 6: the header carries the body's checksum (`body_fnv1a64`). 7: the body ends with the balls'
/// orientations (a tracking flag, then one quaternion per ball when it is on). 8: then the density
/// scaling factors (mass, then inertia; empty when off). Versions 5 (no checksum), 6 and 7 are
/// still read, as models without orientation tracking or density scaling, and every version is
/// validated field by field.
inline constexpr int kSpecimenVersion = 8;

/// Write atomically (temporary file, then rename). Throws std::runtime_error naming the file.
void save_model(const Model& m, const std::string& path, const nlohmann::json& meta = {});

/// What `rocklab genesis -o PATH` writes: PATH.report.json (the genesis report) and the specimen
/// at PATH, the report first, so that a specimen never lacks its report and an error leaves
/// neither behind.
void save_specimen(const Model& m, const std::string& path, const nlohmann::json& meta,
                   const nlohmann::json& report);

/// Read a file written by save_model; `meta` receives the header's "meta" object.
/// Throws InputError naming the file on a wrong format, version, checksum, truncated body or a
/// field out of range (an index that names nothing, a flag that is not 0 or 1, ...).
std::unique_ptr<Model> load_model(const std::string& path, nlohmann::json* meta = nullptr);

} // namespace rocklab
