#include "contact/model_json.hpp"

#include "io/json_input.hpp"

namespace rocklab {

BondOption read_bond_option(JsonObject& p, bool default_bond, double default_hi) {
  BondOption b{default_bond, -1e300, default_hi, false};
  if (!p.has("bond"))
    return b;
  const auto& v = p.raw("bond");
  const auto range = [&](const char* key, double limit) {
    if (!v.is_object() || v.size() != 1 || !v.contains(key))
      return false;
    const auto& r = v[key];
    return r.is_array() && r.size() == 2 && r[0].is_number() && r[1].is_number() &&
           r[0].get<double>() <= r[1].get<double>() && r[0].get<double>() >= -limit &&
           r[1].get<double>() <= limit;
  };
  if (v.is_boolean()) {
    b.bond = v.get<bool>();
  } else if (v.is_number()) {
    b = {true, -1e300, v.get<double>(), false};
  } else if (range("gap", 1e300)) {
    b = {true, v["gap"][0].get<double>(), v["gap"][1].get<double>(), false};
  } else if (range("gap_ratio", 1)) {
    b = {true, v["gap_ratio"][0].get<double>(), v["gap_ratio"][1].get<double>(), true};
  } else {
    p.fail("bond", "expected true/false, a maximum gap in m, {\"gap\": [lo, hi]} in m or "
                   "{\"gap_ratio\": [lo, hi]} as fractions of the radii sum within [-1, 1], "
                   "with lo <= hi, got " +
                       describe(v));
  }
  return b;
}

StiffnessPair read_stiffness_pair(JsonObject& p, const std::string& prefix, const char* k_unit,
                                  bool kn_required) {
  const std::string kn = prefix + "kn", ks = prefix + "ks", emod = prefix + "emod",
                    kratio = prefix + "kratio";
  StiffnessPair s;
  s.deformability = p.has(emod);
  if (s.deformability && (p.has(kn) || p.has(ks)))
    p.fail(emod, "give either the stiffnesses " + kn + "/" + ks + " or the deformability " + emod +
                     "/" + kratio + ", not both");
  if (s.deformability) {
    s.emod = p.number(emod, Range::positive(), std::nullopt, "Pa");
    // Beyond a ratio of 1000 either way the shear or normal stiffness is numerically nil for
    // the time step (fj_kratio 1e308 kept genesis cycling without end).
    s.kratio = p.number(kratio, Range::closed(0, 1e3), 0.0);
    if (s.kratio > 0 && s.kratio < 1e-3)
      p.fail(kratio, "value " + p.raw(kratio).dump() +
                         " is out of range: 0 (no shear stiffness) or [0.001, 1000]");
  } else {
    s.kn = p.number(kn, Range::non_negative(), kn_required ? std::nullopt : std::optional(0.0),
                    k_unit);
    s.ks = p.number(ks, Range::non_negative(), 0.0, k_unit);
  }
  return s;
}

std::vector<std::string> model_names(ModelUse use) {
  std::vector<std::string> names;
  for_each_model([&]<class M>() {
    const bool wanted =
        use == ModelUse::Any || (use == ModelUse::BallFacet && allows_ball_facet<M>()) ||
        (use == ModelUse::Methods && HasMethods<M>) || (use == ModelUse::Inherit && Inherits<M>);
    if (wanted)
      names.emplace_back(M::name);
  });
  return names;
}

ModelKind model_kind_of(std::string_view name) {
  ModelKind kind{};
  bool found = false;
  for_each_model([&]<class M>() {
    if (M::name == name) {
      kind = model_kind<M>;
      found = true;
    }
  });
  if (!found)
    throw std::invalid_argument("unknown contact model '" + std::string(name) + "'");
  return kind;
}

std::vector<std::string> model_methods(ModelKind kind) {
  return visit_model(kind, []<class M>() {
    std::vector<std::string> out;
    if constexpr (HasMethods<M>)
      for (std::string_view m : M::methods)
        out.emplace_back(m);
    return out;
  });
}

bool model_inherits(ModelKind kind) {
  return visit_model(kind, []<class M>() { return Inherits<M>; });
}

bool model_allows_ball_facet(ModelKind kind) {
  return visit_model(kind, []<class M>() { return allows_ball_facet<M>(); });
}

ModelProps read_contact_props(JsonObject& p, std::string_view model, int dim) {
  return visit_model(model_kind_of(model), [&]<class M>() {
    ModelProps props(std::in_place_type<typename M::Props>, M::read(p, dim));
    p.finish();
    return props;
  });
}

nlohmann::json contact_state_json(const ModelBatches& b, ModelKind kind, std::uint32_t slot,
                                  int dim) {
  return visit_model(kind, [&]<class M>() {
    return with_contact<M>(b.of<M>(), slot,
                           [&](const auto&... c) { return M::state_json(c..., dim); });
  });
}

} // namespace rocklab
