#include "lab/calibration/seed_rows.hpp"

#include "io/input_error.hpp"
#include "io/output_dir.hpp"
#include "io/results.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <vector>

namespace fs = std::filesystem;

namespace rocklab::calibration {

namespace {

std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> out(1);
  for (char c : line) {
    if (c == ',')
      out.emplace_back();
    else if (c != '\r')
      out.back() += c;
  }
  return out;
}

} // namespace

SeedRows::SeedRows(std::string path) : path_(std::move(path)) {
  std::ifstream in(path_);
  if (!in)
    return; // no rows yet
  std::string line;
  std::vector<std::string> header;
  for (int n = 1; std::getline(in, line); ++n) {
    if (line.empty())
      continue;
    const std::vector<std::string> cells = split_csv(line);
    auto bad = [&](const std::string& what) {
      throw InputError(path_ + ": line " + std::to_string(n) + ": " + what +
                       " (a per-seed results file: key,seed,property...; remove the line or the "
                       "file to run those seeds again)");
    };
    if (header.empty()) {
      if (cells.size() < 2 || cells[0] != "key" || cells[1] != "seed")
        bad("the header must begin with key,seed");
      header = cells;
      continue;
    }
    if (cells.size() != header.size())
      bad(std::to_string(cells.size()) + " cells where the header has " +
          std::to_string(header.size()));
    if (cells[0].empty())
      bad("no key");
    Row r;
    try {
      std::size_t used = 0;
      r.seed = std::stoull(cells[1], &used);
      if (used != cells[1].size())
        throw std::invalid_argument("seed");
      for (std::size_t k = 2; k < cells.size(); ++k) {
        if (cells[k].empty()) {
          r.properties[header[k]] = nullptr;
          continue;
        }
        const double v = std::stod(cells[k], &used);
        if (used != cells[k].size() || !std::isfinite(v))
          throw std::invalid_argument(header[k]);
        r.properties[header[k]] = v;
      }
    } catch (const std::exception& e) {
      bad(std::string("not a number in column '") + e.what() + "'");
    }
    rows_[cells[0]] = std::move(r);
  }
}

const nlohmann::json* SeedRows::find(const std::string& key) const {
  const auto it = rows_.find(key);
  return it == rows_.end() ? nullptr : &it->second.properties;
}

void SeedRows::add(const std::string& key, std::uint64_t seed, const nlohmann::json& properties) {
  Row r;
  r.seed = seed;
  for (const auto& [k, v] : properties.items()) // numbers only: a null is not measured
    r.properties[k] = v.is_number() && !v.is_boolean() ? v : nlohmann::json(nullptr);
  rows_[key] = std::move(r);
  if (!path_.empty()) {
    if (const fs::path dir = fs::path(path_).parent_path(); !dir.empty())
      fs::create_directories(dir);
    const std::string text = csv();
    write_file_atomically(path_, [&](std::ostream& o) { o << text; });
  }
}

std::string SeedRows::csv() const {
  std::set<std::string> names;
  for (const auto& [key, r] : rows_)
    for (const auto& [k, v] : r.properties.items())
      names.insert(k);
  std::ostringstream s;
  s << "key,seed";
  for (const std::string& n : names)
    s << ',' << n;
  s << '\n';
  for (const auto& [key, r] : rows_) {
    s << key << ',' << r.seed;
    for (const std::string& n : names) {
      s << ',';
      if (r.properties.contains(n) && r.properties[n].is_number())
        s << format_double(r.properties[n].get<double>());
    }
    s << '\n';
  }
  return s.str();
}

} // namespace rocklab::calibration
