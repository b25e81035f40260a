#include "lab/calibration/evaluator.hpp"

#include "io/json_input.hpp"
#include "lab/suite.hpp"
#include "materials/material_card.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace fs = std::filesystem;

namespace rocklab::calibration {

nlohmann::json Evaluator::tests_of(Stage s) const {
  if (s == Stage::Ratios || s == Stage::Final)
    return c_.tests;
  nlohmann::json out = nlohmann::json::array();
  for (const auto& t : c_.tests)
    if (t.value("test", "") == "ucs")
      out.push_back(t);
  return out;
}

Evaluation Evaluator::run(const std::vector<double>& values, Stage s) {
  const nlohmann::json card = apply_params(c_.material, c_.params, values);
  const nlohmann::json tests = tests_of(s);
  std::map<std::string, std::vector<double>> all;
  Evaluation ev;
  for (std::uint64_t seed : c_.seeds) {
    nlohmann::json ts = tests;
    for (auto& t : ts)
      t["seed"] = seed;
    // The cache key: everything the result depends on.
    const std::string key =
        text_hash(card.dump() + "|" + ts.dump() + "|" + ROCKLAB_VERSION).substr(0, 16);
    const fs::path dir = fs::path(o_.out_dir) / "evaluations" / key;
    const fs::path suite_out = dir / "suite";
    if (fs::exists(suite_out / "summary.json")) {
      ++ev.cached;
      ++cached_;
    } else {
      fs::create_directories(dir);
      std::ofstream(dir / "card.json") << card.dump(2) << "\n";
      const nlohmann::json suite{{"name", c_.name + "-" + key},
                                 {"units", "SI"},
                                 {"material", "card.json"},
                                 {"parallel", o_.jobs},
                                 {"tests", ts}};
      std::ofstream(dir / "suite.json") << suite.dump(2) << "\n";
      SuiteOptions so;
      so.out_dir = suite_out.string();
      so.executable = o_.executable;
      so.interrupt = o_.interrupt;
      run_suite(load_suite((dir / "suite.json").string()), so);
      if (o_.interrupt && o_.interrupt->load())
        throw std::runtime_error("interrupted");
      ++run_;
    }
    ev.folders.push_back(suite_out.string());
    const nlohmann::json sm = read_json_file((suite_out / "summary.json").string());
    for (const auto& [k, v] : sm["properties"].items())
      all[k].push_back(v.is_number() ? v.get<double>() : std::nan(""));
  }
  for (const auto& [k, v] : all) {
    double m = 0, q = 0;
    for (double x : v)
      m += x / static_cast<double>(v.size());
    for (double x : v)
      q += (x - m) * (x - m);
    ev.mean[k] = m;
    ev.sd[k] = v.size() > 1 ? std::sqrt(q / static_cast<double>(v.size() - 1)) : 0.0;
  }
  return ev;
}

} // namespace rocklab::calibration
