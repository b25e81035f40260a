#include "io/json_input.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <vector>

namespace rocklab {

bool Range::contains(double v) const {
  if (std::isnan(v))
    return false;
  const bool lo_ok = lo_open ? v > lo : v >= lo;
  const bool hi_ok = hi_open ? v < hi : v <= hi;
  return lo_ok && hi_ok;
}

namespace {
std::string fmt(double v) {
  if (std::isinf(v))
    return v > 0 ? "+inf" : "-inf";
  std::ostringstream s;
  s << v;
  return s.str();
}
} // namespace

std::string Range::str() const {
  std::string s(1, lo_open ? '(' : '[');
  s += fmt(lo);
  s += ", ";
  s += fmt(hi);
  s += hi_open ? ')' : ']';
  return s;
}

void read_units(JsonObject& top) {
  if (top.has("units") && top.string("units") != "SI")
    top.fail("units", "only \"SI\" is supported (m, kg, s, N, Pa)");
}

FileHeader read_header(JsonObject& top, const std::optional<std::string>& default_name) {
  read_units(top);
  FileHeader h;
  h.name = default_name ? top.string("name", *default_name) : top.string("name");
  h.description = top.string("description", "");
  return h;
}

std::string describe(const nlohmann::json& v) {
  std::string s = v.dump();
  if (s.size() > 60)
    s = s.substr(0, 57) + "...";
  return std::string(v.type_name()) + " " + s;
}

namespace {

// While parsing: a key given twice in one object (JSON keeps only the last, silently: a ball with
// "velocity":[1,0],"velocity":[0,0] was taken as at rest) and nesting deeper than any input needs
// (70,000 levels once overflowed the stack) are input errors naming the key path.
class KeyCheck {
public:
  KeyCheck(const std::string& file, Nulls nulls) : file_(file), nulls_(nulls) {}
  bool operator()(int depth, nlohmann::json::parse_event_t ev, nlohmann::json& parsed) {
    using E = nlohmann::json::parse_event_t;
    if (depth > kMaxDepth)
      throw InputError(file_ + ": key '" + where("") + "': nested deeper than " +
                       std::to_string(kMaxDepth) + " levels");
    switch (ev) {
    case E::object_start:
    case E::array_start:
      levels_.push_back({element_label(), ev == E::array_start, 0, {}});
      break;
    case E::object_end:
    case E::array_end:
      if (!levels_.empty())
        levels_.pop_back();
      break;
    case E::key:
      pending_ = parsed.get<std::string>();
      if (!levels_.empty() && !levels_.back().keys.insert(pending_).second)
        throw InputError(file_ + ": key '" + where(pending_) +
                         "' appears twice in one object (only one may be given)");
      break;
    case E::value: {
      const std::string label = element_label();
      if (parsed.is_null() && nulls_ == Nulls::Reject) // "shape": null was taken as no shape
        throw InputError(file_ + ": key '" + where(label) +
                         "': null is not a value here (leave the key out for its default)");
      break;
    }
    }
    return true;
  }

private:
  static constexpr int kMaxDepth = 256;
  struct Level {
    std::string label; ///< its key in the parent object, or "[i]" in the parent array
    bool array = false;
    int next = 0; ///< arrays: the next element's index
    std::set<std::string> keys;
  };
  // The label of the element starting now (an array's next index, or the pending key).
  std::string element_label() {
    if (!levels_.empty() && levels_.back().array) {
      // Appended, not "[" + ...: GCC 12 warns falsely (-Wrestrict) on that operator+.
      std::string label(1, '[');
      label += std::to_string(levels_.back().next++);
      return label += ']';
    }
    return pending_;
  }
  std::string where(const std::string& key) const {
    std::string s;
    for (const Level& l : levels_)
      if (!l.label.empty())
        s += (s.empty() || l.label[0] == '[' ? "" : ".") + l.label;
    if (!key.empty())
      s += (s.empty() || key[0] == '[' ? "" : ".") + key;
    if (s.size() > 80) // deep nesting: the start says where
      s = s.substr(0, 77) + "...";
    return s.empty() ? "<top level>" : s;
  }
  const std::string& file_;
  Nulls nulls_;
  std::vector<Level> levels_;
  std::string pending_;
};

} // namespace

std::string not_an_input_file(const std::string& path) {
  std::error_code ec;
  const auto type = std::filesystem::status(path, ec).type();
  if (type == std::filesystem::file_type::directory)
    return "is a directory, not an input file";
  // A device never ends (/dev/zero was read until memory ran out); a pipe may be given.
  if (type == std::filesystem::file_type::character || type == std::filesystem::file_type::block ||
      type == std::filesystem::file_type::socket)
    return "is a device or socket, not an input file";
  return "";
}

namespace {
// The inputs given as text on this thread, latest last.
thread_local std::vector<std::pair<std::string, std::string>> t_input_texts;
} // namespace

InputText::InputText(std::string name, std::string text) {
  t_input_texts.emplace_back(std::move(name), std::move(text));
}

InputText::~InputText() {
  t_input_texts.pop_back();
}

std::string read_input_text(const std::string& path) {
  for (auto it = t_input_texts.rbegin(); it != t_input_texts.rend(); ++it)
    if (it->first == path)
      return it->second;
  if (const std::string why = not_an_input_file(path); !why.empty())
    throw InputError(path + ": " + why);
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InputError(path + ": cannot open file (missing or unreadable)");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

nlohmann::json read_json_file(const std::string& path, Nulls nulls) {
  const std::string text = read_input_text(path);
  try {
    return nlohmann::json::parse(text, KeyCheck(path, nulls), true, /*ignore_comments=*/true);
  } catch (const nlohmann::json::out_of_range& e) { // a number beyond a double (1e400)
    throw InputError(path + ": malformed JSON: " + e.what() +
                     " (numbers must lie within +-1.8e308)");
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte gives the position; report line and column for a person.
    std::size_t line = 1, col = 1;
    for (std::size_t i = 0; i + 1 < e.byte && i < text.size(); ++i) {
      if (text[i] == '\n') {
        ++line;
        col = 1;
      } else {
        ++col;
      }
    }
    throw InputError(path + ":" + std::to_string(line) + ":" + std::to_string(col) +
                     ": malformed JSON: " + e.what());
  }
}

JsonObject::JsonObject(const nlohmann::json& j, std::string file, std::string path)
    : j_(j), file_(std::move(file)), path_(std::move(path)) {
  if (!j_.is_object())
    throw InputError(file_ + ": key '" + (path_.empty() ? "<top level>" : path_) +
                     "': expected an object, got " + describe(j_));
}

std::string JsonObject::key_path(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

void JsonObject::fail(const std::string& key, const std::string& what) const {
  throw InputError(file_ + ": key '" + key_path(key) + "': " + what);
}

bool JsonObject::has(const std::string& key) const {
  return j_.contains(key);
}

const nlohmann::json& JsonObject::raw(const std::string& key) {
  used_.insert(key);
  if (!j_.contains(key))
    throw InputError(file_ + ": missing required key '" + key_path(key) + "'");
  return j_.at(key);
}

double JsonObject::number(const std::string& key, Range r, std::optional<double> def,
                          const char* unit) {
  used_.insert(key);
  if (!j_.contains(key)) {
    if (def)
      return *def;
    throw InputError(file_ + ": missing required key '" + key_path(key) + "' (a number in " +
                     r.str() + (unit[0] ? std::string(" ") + unit : "") + ")");
  }
  const auto& v = j_.at(key);
  if (!v.is_number())
    fail(key, "expected a number in " + r.str() + ", got " + describe(v));
  const double x = v.get<double>();
  if (!r.contains(x))
    fail(key, "value " + v.dump() + " is out of range " + r.str() +
                  (unit[0] ? std::string(" ") + unit : ""));
  return x;
}

std::int64_t JsonObject::integer(const std::string& key, std::int64_t lo, std::int64_t hi,
                                 std::optional<std::int64_t> def) {
  used_.insert(key);
  std::string range(1, '[');
  range += std::to_string(lo);
  range += ", ";
  range += std::to_string(hi);
  range += ']';
  if (!j_.contains(key)) {
    if (def)
      return *def;
    throw InputError(file_ + ": missing required key '" + key_path(key) + "' (an integer in " +
                     range + ")");
  }
  const auto& v = j_.at(key);
  if (!v.is_number_integer())
    fail(key, "expected an integer in " + range + ", got " + describe(v));
  const std::int64_t x = v.get<std::int64_t>();
  if (x < lo || x > hi)
    fail(key, "value " + v.dump() + " is out of range " + range);
  return x;
}

bool JsonObject::boolean(const std::string& key, std::optional<bool> def) {
  used_.insert(key);
  if (!j_.contains(key)) {
    if (def)
      return *def;
    throw InputError(file_ + ": missing required key '" + key_path(key) + "' (true or false)");
  }
  const auto& v = j_.at(key);
  if (!v.is_boolean())
    fail(key, "expected true or false, got " + describe(v));
  return v.get<bool>();
}

std::string JsonObject::string(const std::string& key, std::optional<std::string> def) {
  used_.insert(key);
  if (!j_.contains(key)) {
    if (def)
      return *def;
    throw InputError(file_ + ": missing required key '" + key_path(key) + "' (a string)");
  }
  const auto& v = j_.at(key);
  if (!v.is_string())
    fail(key, "expected a string, got " + describe(v));
  return v.get<std::string>();
}

std::string JsonObject::choice(const std::string& key, std::initializer_list<const char*> allowed,
                               std::optional<std::string> def) {
  return choice(key, std::vector<std::string>(allowed.begin(), allowed.end()), std::move(def));
}

std::string JsonObject::choice(const std::string& key, const std::vector<std::string>& allowed,
                               std::optional<std::string> def) {
  std::string list;
  for (const std::string& a : allowed) {
    if (!list.empty())
      list += ", ";
    list += '"';
    list += a;
    list += '"';
  }
  if (!j_.contains(key) && !def) {
    used_.insert(key);
    throw InputError(file_ + ": missing required key '" + key_path(key) + "' (one of " + list +
                     ")");
  }
  const std::string v = string(key, def);
  for (const std::string& a : allowed)
    if (v == a)
      return v;
  fail(key, "value \"" + v + "\" is not allowed (one of " + list + ")");
}

Vec3 json_vec(const nlohmann::json& v, int dim, const std::string& file, const std::string& path) {
  const std::string what = dim == 2 ? "2 numbers [x, y]" : "3 numbers [x, y, z]";
  if (!v.is_array() || (v.size() != static_cast<std::size_t>(dim) && !(dim == 2 && v.size() == 3)))
    throw InputError(file + ": key '" + path + "': expected an array of " + what + ", got " +
                     describe(v));
  Vec3 out = Vec3::Zero();
  for (std::size_t k = 0; k < v.size(); ++k) {
    if (!v[k].is_number())
      throw InputError(file + ": key '" + path + "[" + std::to_string(k) +
                       "]': expected a number, got " + describe(v[k]));
    out[static_cast<int>(k)] = v[k].get<double>();
  }
  if (dim == 2 && out.z() != 0)
    throw InputError(file + ": key '" + path + "': value " + v.dump() +
                     " has a non-zero z component; 2D models live in the xy plane");
  return out;
}

Vec3 JsonObject::vec(const std::string& key, int dim, std::optional<Vec3> def, Range r) {
  used_.insert(key);
  if (!j_.contains(key)) {
    if (def)
      return *def;
    throw InputError(file_ + ": missing required key '" + key_path(key) + "'");
  }
  const Vec3 v = json_vec(j_.at(key), dim, file_, key_path(key));
  for (int k = 0; k < 3; ++k)
    if (!(dim == 2 && k == 2) && !r.contains(v[k]))
      fail(key,
           "component " + std::to_string(k) + " = " + fmt(v[k]) + " is out of range " + r.str());
  return v;
}

JsonObject JsonObject::object(const std::string& key) {
  return JsonObject(raw(key), file_, key_path(key));
}

JsonObject JsonObject::optional_object(const std::string& key) {
  static const nlohmann::json empty = nlohmann::json::object();
  if (!j_.contains(key)) {
    used_.insert(key);
    return JsonObject(empty, file_, key_path(key));
  }
  return object(key);
}

std::vector<std::pair<const nlohmann::json*, std::string>> JsonObject::array(const std::string& key,
                                                                             bool required) {
  used_.insert(key);
  std::vector<std::pair<const nlohmann::json*, std::string>> out;
  if (!j_.contains(key)) {
    if (required)
      throw InputError(file_ + ": missing required key '" + key_path(key) + "' (an array)");
    return out;
  }
  const auto& v = j_.at(key);
  if (!v.is_array())
    fail(key, "expected an array, got " + describe(v));
  for (std::size_t i = 0; i < v.size(); ++i)
    out.emplace_back(&v[i], key_path(key) + "[" + std::to_string(i) + "]");
  return out;
}

void JsonObject::finish() const {
  for (auto it = j_.begin(); it != j_.end(); ++it) {
    if (used_.count(it.key()))
      continue;
    std::string allowed;
    for (const auto& u : used_) {
      if (!allowed.empty())
        allowed += ", ";
      allowed += u;
    }
    throw InputError(file_ + ": unknown key '" + key_path(it.key()) +
                     "' (allowed here: " + allowed + ")");
  }
}

std::vector<std::string> JsonObject::unread() const {
  std::vector<std::string> keys;
  for (auto it = j_.begin(); it != j_.end(); ++it)
    if (!used_.count(it.key()))
      keys.push_back(it.key());
  return keys;
}

std::uint64_t fnv1a64(std::string_view text, std::uint64_t h) {
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  return h;
}

std::string hash_hex(std::uint64_t h) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

std::string text_hash(std::string_view text) {
  return hash_hex(fnv1a64(text));
}

} // namespace rocklab
