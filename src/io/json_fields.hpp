// Named fields of a struct in a JSON object, written and read by one `fields(Archive&)` function
// per struct (the named twin of the specimen file's binary archive): checkpoint state. Reading
// checks every field's presence and type and fails with an InputError naming the file and key.
#pragma once

#include "core/types.hpp"
#include "io/input_error.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace rocklab {

inline nlohmann::json vec3_to_json(const Vec3& v) {
  return nlohmann::json::array({v.x(), v.y(), v.z()});
}

/// Writes fields into `j`.
struct JsonFieldWriter {
  nlohmann::json& j;
  static constexpr bool reading = false;

  template <class T> void operator()(const char* name, const T& v) { j[name] = v; }
  void operator()(const char* name, const Vec3& v) { j[name] = vec3_to_json(v); }
  void operator()(const char* name, const std::vector<Vec3>& v) {
    nlohmann::json a = nlohmann::json::array();
    for (const Vec3& x : v)
      a.push_back(vec3_to_json(x));
    j[name] = std::move(a);
  }
  /// A nested struct with its own fields(), as an object.
  template <class T> void object(const char* name, T& v) {
    nlohmann::json sub = nlohmann::json::object();
    JsonFieldWriter w{sub};
    v.fields(w);
    j[name] = std::move(sub);
  }
  /// A list of structs with their own fields(), as an array of objects.
  template <class T> void objects(const char* name, std::vector<T>& v) {
    nlohmann::json a = nlohmann::json::array();
    for (T& x : v) {
      nlohmann::json sub = nlohmann::json::object();
      JsonFieldWriter w{sub};
      x.fields(w);
      a.push_back(std::move(sub));
    }
    j[name] = std::move(a);
  }
};

/// Reads fields back from `j`; `file` names the checkpoint in errors.
struct JsonFieldReader {
  const nlohmann::json& j;
  std::string file;
  static constexpr bool reading = true;

  const nlohmann::json& at(const char* name) const {
    if (!j.is_object() || !j.contains(name))
      throw InputError(file + ": corrupt checkpoint (state field '" + name + "' is missing)");
    return j[name];
  }
  [[noreturn]] void bad(const char* name) const {
    throw InputError(file + ": corrupt checkpoint (state field '" + name +
                     "' has the wrong type or size)");
  }
  template <class T> void operator()(const char* name, T& v) {
    try {
      v = at(name).template get<T>();
    } catch (const nlohmann::json::exception&) {
      bad(name);
    }
  }
  void operator()(const char* name, Vec3& v) { v = vec3(at(name), name); }
  void operator()(const char* name, std::vector<Vec3>& v) {
    const nlohmann::json& a = at(name);
    if (!a.is_array())
      bad(name);
    v.clear();
    for (const auto& x : a)
      v.push_back(vec3(x, name));
  }
  template <class T> void object(const char* name, T& v) {
    JsonFieldReader r{at(name), file};
    v.fields(r);
  }
  template <class T> void objects(const char* name, std::vector<T>& v) {
    const nlohmann::json& a = at(name);
    if (!a.is_array())
      bad(name);
    v.assign(a.size(), T{});
    for (std::size_t k = 0; k < a.size(); ++k) {
      JsonFieldReader r{a[k], file};
      v[k].fields(r);
    }
  }

private:
  Vec3 vec3(const nlohmann::json& x, const char* name) const {
    if (!x.is_array() || x.size() != 3 || !x[0].is_number() || !x[1].is_number() ||
        !x[2].is_number())
      bad(name);
    return Vec3(x[0].get<double>(), x[1].get<double>(), x[2].get<double>());
  }
};

} // namespace rocklab
