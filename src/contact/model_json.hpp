// Contact models in JSON files, for every model of the registry: properties read from a scene's
// contact_models entry, the state written to results.json, and the names a file may use.
#pragma once

#include "contact/registry.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <string_view>
#include <vector>

namespace rocklab {

class JsonObject;

/// What a list of model names is for.
enum class ModelUse {
  Any,       ///< every model
  BallFacet, ///< models allowed at ball-facet contacts
  Methods,   ///< models with methods (scene `methods`)
  Inherit    ///< models that inherit surface properties
};
/// Model keywords in registry order.
std::vector<std::string> model_names(ModelUse use = ModelUse::Any);
/// The kind of a model keyword (which must be one of model_names()).
ModelKind model_kind_of(std::string_view name);
/// The method names of a model (empty if it has none).
std::vector<std::string> model_methods(ModelKind kind);
/// True if the model of this kind inherits surface properties.
bool model_inherits(ModelKind kind);
/// True if the model may be installed at ball-facet contacts.
bool model_allows_ball_facet(ModelKind kind);

/// The properties of one contact model from the keys of a contact_models entry (every key must be
/// known; docs/scene-format.md).
ModelProps read_contact_props(JsonObject& p, std::string_view model, int dim);

/// Model state of one contact (per-element state for flat joints), SI units.
nlohmann::json contact_state_json(const ModelBatches& b, ModelKind kind, std::uint32_t slot,
                                  int dim);

} // namespace rocklab
