// Material genesis: turn a material card into a specimen (packed, stressed, finalized, released).
// Units: SI.
#pragma once

#include "core/model.hpp"
#include "materials/material_card.hpp"

#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace rocklab {

struct GenesisReport {
  int dim = 3;
  std::int64_t grains = 0, floaters = 0;
  std::int64_t escaped = 0; ///< grains removed because their centre left the vessel
  std::int64_t contacts = 0, clumps = 0, linear = 0, smoothjoint = 0;
  /// Bond candidates by what they became: "<model>_<count>" (e.g. "flatjoint_slit", the card's
  /// bonded model's card_counts); bonds(key) reads 0 for one never made.
  std::map<std::string, std::int64_t> bonds;
  /// The key of `bonds`: "<model>_<count>" (e.g. "flatjoint_slit").
  static std::string bond_key(std::string_view model, std::string_view count) {
    return std::string(model) + "_" + std::string(count);
  }
  std::int64_t bonded(const std::string& key) const {
    const auto it = bonds.find(key);
    return it == bonds.end() ? 0 : it->second;
  }
  ShapeSpec shape; ///< the specimen: the vessel at the end of installation, or the cut [m]
  double porosity_target = 0;
  double porosity_packed = 0;    ///< when the friction control reached the target
  double porosity_installed = 0; ///< of the vessel at the end of installation
  double porosity = 0;         ///< of the specimen: installed, or of the cut shape when one is cut
  double packing_friction = 0; ///< grain friction the packing ended with
  double coordination = 0;     ///< mean ball-ball contacts carrying force per grain (no floaters)
  double pressure = 0;         ///< requested installation pressure [Pa]
  std::vector<std::pair<std::string, double>> wall_stress; ///< at the end of installation [Pa]
  double residual_mean_stress = 0; ///< after release [Pa], compression positive
  std::int64_t steps_packing = 0, steps_installation = 0, steps_release = 0;
  double seconds = 0;
  nlohmann::json to_json() const;
  nlohmann::json contact_counts() const; ///< the report's "contacts"
};

struct GenesisResult {
  std::unique_ptr<Model> model;
  GenesisReport report;
};

/// The metadata a specimen file made by genesis carries: rocklab version, the material card
/// (file, name, hash, its JSON), the seed and the genesis report (without its wall time, so the
/// specimen's bytes depend only on the inputs).
nlohmann::json specimen_meta(const MaterialCard& card, const GenesisReport& report);

/// Run material genesis. Throws PhysicsError on blow-up and std::runtime_error when a phase does
/// not reach its criterion within the card's max_cycles.
/// `interrupt` (optional) is polled between chunks of cycles; when set, genesis throws.
GenesisResult run_genesis(const MaterialCard& card,
                          const std::function<void(const std::string&)>& progress = {},
                          const std::atomic<bool>* interrupt = nullptr);

/// What genesis of `card` with `o` applied will take, as its progress line says it: "estimate:
/// about N grains, M MB, T on one core" ("" for an imported packing). Throws InputError naming
/// the key for a card that cannot finish (genesis/estimate.cpp), so a caller can refuse it
/// before any work starts.
std::string genesis_estimate(MaterialCard card, const GenesisOverrides& o);

/// The one path from a card to a specimen, for `rocklab genesis` and a protocol's
/// `specimen.material`: the overrides applied to the card (a bad shape fails naming where it was
/// given), then genesis with a "genesis" progress line on stderr when `progress`.
GenesisResult genesis_with_overrides(MaterialCard& card, const GenesisOverrides& o, bool progress,
                                     const std::atomic<bool>* interrupt);

} // namespace rocklab
