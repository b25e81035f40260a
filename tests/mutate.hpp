// Mutations of JSON input files for the robustness tests (tests/test_robustness.cpp): half of them
// keep the file valid JSON and change one value, key or structure to something hostile (a value
// out of range, of the wrong type, a duplicate key, deep nesting, a number beyond a double), half
// change its bytes (a flipped byte, a span deleted or repeated, a truncation).
#pragma once

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace rocklab::test {

namespace mutate_detail {

using Json = nlohmann::ordered_json;

inline std::size_t pick(std::mt19937_64& rng, std::size_t n) {
  return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng);
}

inline void pointers(const Json& j, const Json::json_pointer& at,
                     std::vector<Json::json_pointer>& out) {
  out.push_back(at);
  if (j.is_object())
    for (const auto& [k, v] : j.items())
      pointers(v, at / k, out);
  else if (j.is_array())
    for (std::size_t i = 0; i < j.size(); ++i)
      pointers(j[i], at / i, out);
}

inline Json hostile(std::mt19937_64& rng) {
  static const char* values[] = {"0",
                                 "-1",
                                 "1",
                                 "0.5",
                                 "2",
                                 "1e308",
                                 "-1e308",
                                 "1e-320",
                                 "1e30",
                                 "-1e-30",
                                 "9223372036854775807",
                                 "18446744073709551615",
                                 "-9223372036854775808",
                                 "\"\"",
                                 "\"x\"",
                                 "\"/dev/zero\"",
                                 "\"../../../../../../etc/passwd\"",
                                 "true",
                                 "false",
                                 "[]",
                                 "{}",
                                 "[0, 0, 0]",
                                 "[1e308, 1e308, 1e308]",
                                 "[-1, -1]",
                                 "[1e-9, 2e-9]",
                                 "{\"a\": 1}",
                                 "null"};
  return Json::parse(values[pick(rng, std::size(values))]);
}

// `text` with the value at `ptr` replaced by raw text (which need not be valid JSON by itself).
inline std::string splice(Json j, const Json::json_pointer& ptr, const std::string& raw) {
  const std::string mark = "\x01rocklab-mutation\x01";
  j[ptr] = mark;
  std::string s = j.dump(1);
  const std::string quoted = Json(mark).dump();
  s.replace(s.find(quoted), quoted.size(), raw);
  return s;
}

inline std::string structural(const std::string& text, std::mt19937_64& rng) {
  Json j = Json::parse(text);
  std::vector<Json::json_pointer> all;
  pointers(j, Json::json_pointer(), all);
  const Json::json_pointer p = all.size() > 1 ? all[1 + pick(rng, all.size() - 1)] : all[0];
  switch (pick(rng, 8)) {
  case 0:
  case 1:
    if (!p.empty())
      j[p] = hostile(rng);
    break;
  case 2: // a number scaled by 10^k or negated
    if (j[p].is_number()) {
      const double v = j[p].get<double>();
      const int k = static_cast<int>(pick(rng, 25)) - 12;
      j[p] = pick(rng, 4) == 0 ? -v : v * std::pow(10.0, k);
    } else {
      j[p] = hostile(rng);
    }
    break;
  case 3: // a key or element removed
    if (!p.empty()) {
      Json& parent = j[p.parent_pointer()];
      if (parent.is_object())
        parent.erase(p.back());
      else if (parent.is_array())
        parent.erase(parent.begin() + static_cast<long>(std::stoul(p.back())));
    }
    break;
  case 4: // an unknown key
    if (j[p].is_object())
      j[p]["rocklab_unknown_key"] = 1;
    else
      j[p.parent_pointer()].is_object() ? void(j[p.parent_pointer()]["colour"] = "red")
                                        : void(j[p] = hostile(rng));
    break;
  case 5: // a key given twice (the second value hostile)
    if (!p.empty() && j[p.parent_pointer()].is_object())
      return splice(j, p, j[p].dump() + ", \"" + p.back() + "\": " + hostile(rng).dump());
    break;
  case 6: // nesting deeper than any reader should follow
  {
    const std::size_t n = 257 + pick(rng, 70000);
    return splice(j, p, std::string(n, '[') + std::string(n, ']'));
  }
  default: // a number beyond a double
    return splice(j, p, pick(rng, 2) ? "1e400" : "-1e999");
  }
  return j.dump(1);
}

inline std::string bytes(std::string s, std::mt19937_64& rng) {
  if (s.empty())
    return "{";
  const std::size_t at = pick(rng, s.size());
  const std::size_t len = 1 + pick(rng, std::min<std::size_t>(40, s.size() - at));
  switch (pick(rng, 4)) {
  case 0:
    s[at] = static_cast<char>(pick(rng, 256));
    break;
  case 1:
    s.erase(at, len);
    break;
  case 2:
    s.insert(at, s.substr(at, len));
    break;
  default:
    s.resize(at);
  }
  return s;
}

} // namespace mutate_detail

/// One mutant of a JSON text, drawn with `rng`.
inline std::string mutate(const std::string& text, std::mt19937_64& rng) {
  return mutate_detail::pick(rng, 2) ? mutate_detail::structural(text, rng)
                                     : mutate_detail::bytes(text, rng);
}

} // namespace rocklab::test
