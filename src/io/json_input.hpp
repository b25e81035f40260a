// Validated reading of JSON input files. Every error names the file, the key (as a path such as
// `balls[3].radius`), the offending value and the allowed range, and is thrown as InputError.
#pragma once

#include "core/types.hpp"
#include "io/input_error.hpp"

#include <nlohmann/json.hpp>

#include <initializer_list>
#include <limits>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace rocklab {

/// An interval of allowed values; open or closed at each end.
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = true, hi_open = true;
  bool contains(double v) const;
  std::string str() const;

  static Range any() { return {}; }
  static Range positive() { return {0, std::numeric_limits<double>::infinity(), true, true}; }
  static Range non_negative() { return {0, std::numeric_limits<double>::infinity(), false, true}; }
  static Range closed(double a, double b) { return {a, b, false, false}; }
  static Range half_open(double a, double b) { return {a, b, false, true}; }
  static Range at_least(double a) {
    return {a, std::numeric_limits<double>::infinity(), false, true};
  }
  /// A material density [kg/m^3]: up to 1e6, some 40 times osmium's (the densest element, 22,590);
  /// beyond that no grain is a rock, and 1e308 overflowed the masses into NaN results.
  static Range density() { return {0, 1e6, true, false}; }
};

class JsonObject;
/// The header key every input file may give, read in one place: `units`, which must be "SI" (m, kg,
/// s, N, Pa) when given.
void read_units(JsonObject& top);

/// The header every input file may give, read in one place (read_header): its name and
/// description (free text).
struct FileHeader {
  std::string name, description;
};
/// `units` (read_units), `name` (required where `default_name` is nullopt) and `description`.
FileHeader read_header(JsonObject& top, const std::optional<std::string>& default_name);

/// Why `path` cannot be an input file (a directory, a device or a socket), or "".
std::string not_an_input_file(const std::string& path);
/// The bytes of an input file; a directory, a device or an unreadable file is an input error.
/// A name given to an InputText living on this thread reads as its text instead of the disk.
std::string read_input_text(const std::string& path);

/// An input given as text rather than as a file (the Python module's dict arguments): while it
/// lives, read_input_text(name) on this thread returns `text`, so every loader reads it as it reads
/// a file, and its errors name `name`. Relative paths in it resolve against the directory of
/// `name` (the working directory for a bare name such as "<card dict>"). Names nest: the latest
/// given wins until it ends. Not shared with other threads or child processes.
class InputText {
public:
  InputText(std::string name, std::string text);
  ~InputText();
  InputText(const InputText&) = delete;
  InputText& operator=(const InputText&) = delete;
};
/// Parse a JSON file; syntax errors name the file, line and column. A key given twice in one
/// object, nesting deeper than 256 levels and (in input files, not in rocklab's own outputs read
/// back) a null value are input errors naming the key path.
enum class Nulls { Reject, Allow };
nlohmann::json read_json_file(const std::string& path, Nulls nulls = Nulls::Reject);

/// FNV-1a 64-bit hash of bytes, as 16 hex digits (stable across platforms): input texts for the
/// caches, specimen and checkpoint bodies for their checksum. Any single changed byte changes it.
std::string text_hash(std::string_view text);
/// The FNV-1a 64 hash of `text` continued from `h` (text_hash is its start, in 16 hex digits):
/// for hashing a long text a piece at a time.
std::uint64_t fnv1a64(std::string_view text, std::uint64_t h = 1469598103934665603ULL);
/// A hash as text_hash prints it.
std::string hash_hex(std::uint64_t h);

/// A JSON object being read: tracks the keys used so unknown keys can be reported.
class JsonObject {
public:
  JsonObject(const nlohmann::json& j, std::string file, std::string path);

  bool has(const std::string& key) const;
  const nlohmann::json& raw(const std::string& key);
  std::string key_path(const std::string& key) const;

  double number(const std::string& key, Range r, std::optional<double> def = std::nullopt,
                const char* unit = "");
  std::int64_t integer(const std::string& key, std::int64_t lo, std::int64_t hi,
                       std::optional<std::int64_t> def = std::nullopt);
  bool boolean(const std::string& key, std::optional<bool> def = std::nullopt);
  std::string string(const std::string& key, std::optional<std::string> def = std::nullopt);
  std::string choice(const std::string& key, std::initializer_list<const char*> allowed,
                     std::optional<std::string> def = std::nullopt);
  std::string choice(const std::string& key, const std::vector<std::string>& allowed,
                     std::optional<std::string> def = std::nullopt);
  /// A vector of `dim` numbers (2D input may give 2 components; z is then 0).
  Vec3 vec(const std::string& key, int dim, std::optional<Vec3> def = std::nullopt,
           Range r = Range::any());
  JsonObject object(const std::string& key);
  /// An optional sub-object: a missing key reads as {} (every key inside takes its default).
  JsonObject optional_object(const std::string& key);
  /// Array elements, with their paths, for the caller to read.
  std::vector<std::pair<const nlohmann::json*, std::string>> array(const std::string& key,
                                                                   bool required = true);
  /// Fail on keys that were never read.
  void finish() const;
  /// The keys present and not read so far (in the object's order).
  std::vector<std::string> unread() const;
  /// Whether `key` was read (present or not).
  bool was_read(const std::string& key) const { return used_.count(key) > 0; }

  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }
  const nlohmann::json& json() const { return j_; } ///< the object as given (nothing marked read)
  [[noreturn]] void fail(const std::string& key, const std::string& what) const;

private:
  const nlohmann::json& j_;
  std::string file_, path_;
  std::set<std::string> used_;
};

/// Read a vector from a bare JSON value (for array elements).
Vec3 json_vec(const nlohmann::json& v, int dim, const std::string& file, const std::string& path);

std::string describe(const nlohmann::json& v);

} // namespace rocklab
