// The card readers every bonded model's card section shares (card_bonding.hpp). Units SI.
#include "contact/card_bonding.hpp"

namespace rocklab {

Distribution read_distribution(JsonObject& o, const std::string& key, const char* unit) {
  Distribution d;
  if (!o.has(key))
    o.fail(key, std::string("missing (a number or {\"mean\", \"sd\"} in ") + unit + ")");
  const auto& v = o.raw(key);
  if (v.is_number()) {
    d.mean = v.get<double>();
    if (d.mean < 0)
      o.fail(key, "value " + v.dump() + " is out of range [0, +inf) " + unit);
    return d;
  }
  JsonObject m(v, o.file(), o.key_path(key));
  d.mean = m.number("mean", Range::non_negative(), std::nullopt, unit);
  d.sd = m.number("sd", Range::non_negative(), 0.0, unit);
  m.finish();
  return d;
}

double take_card_sd(nlohmann::json& keys, const std::string& file, const std::string& path,
                    const char* key, const char* unit) {
  const auto it = keys.find(key);
  if (it == keys.end() || !it->is_object())
    return 0;
  JsonObject d(*it, file, path + "." + key);
  const double mean = d.number("mean", Range::any(), std::nullopt, unit); // the model's range
  const double sd = d.number("sd", Range::non_negative(), 0.0, unit);
  d.finish();
  *it = mean;
  return sd;
}

nlohmann::json card_model_keys(JsonObject& top, const std::string& section,
                               const std::string& prefix,
                               std::initializer_list<const char*> card_keys) {
  JsonObject s = top.object(section);
  nlohmann::json keys = s.json(); // an object (JsonObject checked it)
  for (const char* k : card_keys)
    keys.erase(k);
  for (auto it = keys.begin(); it != keys.end(); ++it)
    if (!prefix.empty() && it.key().rfind(prefix, 0) != 0)
      s.fail(it.key(), "is not a key of a card's '" + section + "' section (its keys start with '" +
                           prefix +
                           "'; the linear part is the card's 'linear' section and "
                           "genesis installs the bonds)");
  return keys;
}

} // namespace rocklab
