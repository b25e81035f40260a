#include "lab/suite.hpp"

#include "io/json_input.hpp"
#include "io/output_dir.hpp"
#include "io/results.hpp"
#include "lab/frame/frame_test.hpp"
#include "lab/protocol.hpp"
#include "lab/protocol_table.hpp"
#include "lab/suite_jobs.hpp"
#include "materials/genesis.hpp"
#include "materials/material_card.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <thread>

namespace rocklab {

namespace fs = std::filesystem;

namespace {

bool valid_name(const std::string& s) {
  if (s.empty() || s.size() > 64)
    return false;
  return std::all_of(s.begin(), s.end(),
                     [](char c) {
                       return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' ||
                              c == '.';
                     }) &&
         s[0] != '.';
}

} // namespace

Suite load_suite(const std::string& path) {
  Suite s;
  s.file = path;
  const nlohmann::json j = read_json_file(path);
  s.text_hash = text_hash(read_input_text(path));
  JsonObject top(j, path, "");
  read_units(top);
  s.name = top.string("name", fs::path(path).stem().string());
  top.string("description", "");
  {
    const std::string m = top.string("material");
    s.material_file = resolve(path, m);
    if (!fs::exists(s.material_file))
      top.fail("material", "\"" + s.material_file + "\" does not exist");
    s.material = read_json_file(s.material_file);
    load_material_card(s.material_file); // validate the card now, not in a child process
  }
  s.parallel = static_cast<int>(top.integer("parallel", 0, 256, 0));
  std::set<std::string> names;
  for (const auto& [tj, tpath] : top.array("tests")) {
    if (!tj->is_object())
      throw InputError(path + ": key '" + tpath + "': a test must be an object");
    SuiteTest t;
    nlohmann::json pj = *tj;
    JsonObject tobj(*tj, path, tpath);
    t.name = tobj.string("name");
    if (!valid_name(t.name))
      tobj.fail("name", "\"" + t.name + "\" must be 1-64 letters, digits, '_', '-' or '.'");
    if (!names.insert(t.name).second)
      tobj.fail("name", "\"" + t.name + "\" is used by two tests");
    if (tobj.has("specimen"))
      tobj.fail("specimen", "a suite's tests use the suite's material; give \"shape\" (and "
                            "\"seed\") in the test instead");
    if (tobj.has("shape"))
      t.shape = tobj.raw("shape");
    if (tobj.has("cut"))
      t.cut = tobj.raw("cut");
    pj.erase("name");
    pj.erase("shape");
    pj.erase("cut");
    t.protocol = pj;
    // Validate the protocol now (it will be given its specimen when the suite runs).
    nlohmann::json check = pj;
    check["specimen"] = {{"material", fs::absolute(s.material_file).string()}};
    if (!t.shape.is_null())
      check["specimen"]["shape"] = t.shape;
    if (!t.cut.is_null())
      check["specimen"]["cut"] = t.cut;
    const Protocol p = protocol_from_json(check, path, tpath);
    if (!t.shape.is_null())
      shape_from_json(t.shape, s.material.value("dimension", 3), path, tpath + ".shape");
    if (!t.cut.is_null())
      shape_from_json(t.cut, s.material.value("dimension", 3), path, tpath + ".cut", true);
    t.specimen_key =
        t.shape.dump() + "|" + t.cut.dump() + "|" + (p.seed ? std::to_string(*p.seed) : "card");
    s.tests.push_back(std::move(t));
  }
  if (s.tests.empty())
    top.fail("tests", "a suite needs at least one test");
  top.finish();
  return s;
}

namespace {

std::string last_lines(const std::string& file, int n) {
  const std::string t = read_input_text(file);
  std::size_t pos = t.size();
  for (int k = 0; k <= n && pos > 0; ++k)
    pos = t.rfind('\n', pos - 1);
  return pos == std::string::npos ? t : t.substr(pos + 1);
}

double num(const nlohmann::json& r, const char* key) {
  return json_number(r, key, std::nan(""));
}

} // namespace

namespace {

// A suite in progress: the staging folder, the process and thread counts, the material.
struct SuiteRun {
  SuiteRun(const Suite& suite, const SuiteOptions& options, OutputDir& dir)
      : s(suite), o(options), out(dir) {}

  const Suite& s;
  const SuiteOptions& o;
  OutputDir& out;
  int parallel = 1, threads = 1;
  unsigned cores = 1;
  std::string material;

  std::map<std::string, std::string> make_specimens();
  std::vector<Job> run_tests(const std::map<std::string, std::string>& specimen_of);
};

// 1. One genesis per specimen shared by several tests; returns specimen key -> file name under
// specimens/.
std::map<std::string, std::string> SuiteRun::make_specimens() {
  std::map<std::string, int> uses;
  for (const SuiteTest& t : s.tests)
    ++uses[t.specimen_key];
  std::map<std::string, std::string> specimen_of;
  std::vector<Job> gen;
  for (const SuiteTest& t : s.tests) {
    if (uses[t.specimen_key] < 2 || specimen_of.count(t.specimen_key))
      continue;
    const std::string name = "specimen" + std::to_string(specimen_of.size() + 1) + ".rlspec";
    specimen_of[t.specimen_key] = name;
    Job j;
    j.label = "genesis " + name;
    j.argv = {o.executable, "genesis", material, "-o", out.staged("specimens/" + name).string(),
              "--threads",  "THREADS", "-q"};
    if (!t.shape.is_null())
      j.argv.insert(j.argv.end(), {"--shape", t.shape.dump()});
    if (!t.cut.is_null())
      j.argv.insert(j.argv.end(), {"--cut", t.cut.dump()});
    if (t.protocol.contains("seed"))
      j.argv.insert(j.argv.end(), {"--seed", t.protocol["seed"].dump()});
    j.log = out.staged("logs/" + name + ".log").string();
    gen.push_back(std::move(j));
  }
  // Fewer genesis jobs than processes: each gets a larger share of the cores.
  const int gen_jobs = std::max(1, std::min(parallel, static_cast<int>(gen.size())));
  const int gen_threads =
      o.threads > 0 ? o.threads : std::max(1, static_cast<int>(cores) / gen_jobs);
  for (Job& j : gen)
    std::replace(j.argv.begin(), j.argv.end(), std::string("THREADS"), std::to_string(gen_threads));
  run_jobs(gen, parallel, o);
  for (const Job& j : gen)
    if (j.status != 0)
      throw std::runtime_error(s.file + ": " + j.label + " failed:\n" + last_lines(j.log, 5));

  return specimen_of;
}

// 2. The tests (a specimen used once is made inside its test).
std::vector<Job> SuiteRun::run_tests(const std::map<std::string, std::string>& specimen_of) {
  std::vector<Job> jobs;
  for (const SuiteTest& t : s.tests) {
    nlohmann::json p = t.protocol;
    if (specimen_of.count(t.specimen_key)) {
      p["specimen"] = {{"file", "../../specimens/" + specimen_of.at(t.specimen_key)}};
      p.erase("seed");
    } else {
      p["specimen"] = {{"material", material}};
      if (!t.shape.is_null())
        p["specimen"]["shape"] = t.shape;
      if (!t.cut.is_null())
        p["specimen"]["cut"] = t.cut;
    }
    if (!p.contains("name"))
      p["name"] = t.name;
    const fs::path dir = out.staged("tests/" + t.name);
    fs::create_directories(dir);
    write_text_file(dir / "protocol.json", p.dump(2) + "\n");
    Job j;
    j.label = "test " + t.name;
    j.argv = {o.executable,           "test",      (dir / "protocol.json").string(), "-o",
              (dir / "out").string(), "--threads", std::to_string(threads),          "-q"};
    j.log = out.staged("logs/" + t.name + ".log").string();
    jobs.push_back(std::move(j));
  }
  run_jobs(jobs, parallel, o);

  return jobs;
}

// The headline properties, in the order rock engineers read them (E, nu, strengths, envelope):
// summary.csv and the printed table show them first, then every other property a test declares
// (table order).
constexpr const char* kHeadline[] = {
    "youngs_modulus_Pa", "poisson_ratio",      "ucs_Pa",      "bts_Pa",       "direct_tension_Pa",
    "ucs_over_bts",      "friction_angle_deg", "cohesion_Pa", "hoek_brown_mi"};

// Every property the frame tests declare, in table order, each once.
std::vector<std::string> declared_properties() {
  std::vector<std::string> names;
  for (const std::string& test : frame_test_names())
    for (const SuiteProperty& p : make_frame_test(test)->suite_properties())
      if (std::find(names.begin(), names.end(), p.name) == names.end())
        names.emplace_back(p.name);
  return names;
}

// 3. The summary of the tests' results.
struct SuiteSummary {
  nlohmann::json tests = nlohmann::json::array();
  SuiteValues values; ///< what each test's results gave (the tests' own add_to_suite)
  nlohmann::json warnings = nlohmann::json::array(); ///< every test's, as "NAME: what"
  bool failed = false;
  std::string csv = "name,test,status,confinement_Pa,youngs_modulus_Pa,poisson_ratio,"
                    "peak_stress_Pa,peak_deviator_Pa,tensile_strength_Pa,cracks_tension,"
                    "cracks_shear,grains,steps,wall_time_s\n";

  void add(const SuiteTest& t, const Job& j, OutputDir& out);
  nlohmann::json properties() const;
};

void SuiteSummary::add(const SuiteTest& t, const Job& j, OutputDir& out) {
  // Move the test's output folder up: tests/NAME/{protocol.json, results.json, ...}.
  const fs::path dir = out.staged("tests/" + t.name);
  nlohmann::json row{{"name", t.name}, {"test", t.protocol.value("test", "")}};
  if (j.status != 0) {
    failed = true;
    row["status"] = "failed";
    row["exit_status"] = j.status;
    row["error"] = last_lines(j.log, 3);
    tests.push_back(row);
    csv += t.name + "," + row["test"].get<std::string>() + ",failed,,,,,,,,,,," +
           format_double(j.seconds) + "\n";
    return;
  }
  for (const auto& entry : fs::directory_iterator(dir / "out"))
    fs::rename(entry.path(), dir / entry.path().filename());
  fs::remove(dir / "out");
  const nlohmann::json r = read_json_file((dir / "results.json").string(), Nulls::Allow);
  row["status"] = "ok";
  row["results"] = "tests/" + t.name + "/results.json";
  const double conf = num(r, "confinement_Pa");
  row["confinement_Pa"] = number_or_null(conf);
  for (const char* key : {"youngs_modulus_Pa", "poisson_ratio", "peak_stress_Pa",
                          "peak_deviator_Pa", "tensile_strength_Pa"})
    row[key] = number_or_null(num(r, key));
  row["cracks"] = r["cracks"];
  if (r.contains("warnings")) {
    row["warnings"] = r["warnings"];
    for (const auto& w : r["warnings"])
      warnings.push_back(t.name + ": " + w.get<std::string>());
  }
  row["wall_time_s"] = r["provenance"]["wall_time_s"];
  row["grains"] = r["provenance"]["grains"];
  row["steps"] = r["provenance"]["steps"];
  const std::string type = r.value("test", "");
  if (const std::unique_ptr<FrameTest> test = make_frame_test(type))
    test->add_to_suite(r, values);
  auto f = [&](const char* key) {
    const double v = num(r, key);
    return std::isfinite(v) ? format_double(v) : std::string();
  };
  csv += t.name + "," + type + ",ok," + f("confinement_Pa") + "," + f("youngs_modulus_Pa") + "," +
         f("poisson_ratio") + "," + f("peak_stress_Pa") + "," + f("peak_deviator_Pa") + "," +
         f("tensile_strength_Pa") + "," + r["cracks"]["tension"].dump() + "," +
         r["cracks"]["shear"].dump() + "," + r["provenance"]["grains"].dump() + "," +
         r["provenance"]["steps"].dump() + "," + format_double(j.seconds) + "\n";
  tests.push_back(row);
}

// Every frame test adds its part, whichever tests this suite ran (a property no test measured is
// null).
nlohmann::json SuiteSummary::properties() const {
  nlohmann::json props = nlohmann::json::object();
  for (const std::string& name : frame_test_names())
    make_frame_test(name)->suite_results(values, props);
  return props;
}

} // namespace

std::vector<std::string> summary_columns() {
  std::vector<std::string> cols(std::begin(kHeadline), std::end(kHeadline));
  for (const std::string& name : declared_properties())
    if (std::find(cols.begin(), cols.end(), name) == cols.end())
      cols.push_back(name);
  return cols;
}

void say_genesis_estimates(const std::string& card_file, const std::string& file,
                           const std::vector<TestShape>& tests, const char* tag, bool print) {
  const MaterialCard card = load_material_card(card_file);
  std::set<std::string> seen; // one line per distinct specimen
  for (std::size_t k = 0; k < tests.size(); ++k) {
    const TestShape& t = tests[k];
    if (!seen.insert(t.shape.dump() + t.cut.dump()).second)
      continue;
    const std::string at = "tests[" + std::to_string(k) + "]";
    const std::string line = genesis_estimate(
        card, {{t.shape, file, at + ".shape"}, {t.cut, file, at + ".cut"}, std::nullopt});
    if (print && !line.empty())
      std::fprintf(stderr, "[rocklab %s] %s: genesis %s\n", tag, t.name.c_str(), line.c_str());
  }
}

nlohmann::json run_suite(const Suite& s, const SuiteOptions& o) {
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  std::vector<TestShape> shapes;
  for (const SuiteTest& t : s.tests)
    shapes.push_back({t.name, t.shape, t.cut});
  say_genesis_estimates(s.material_file, s.file, shapes, "suite", o.progress);
  OutputDir out(o.out_dir);
  SuiteRun run(s, o, out);
  run.cores = std::max(1u, std::thread::hardware_concurrency());
  run.parallel = s.parallel > 0 ? s.parallel
                                : static_cast<int>(std::min<std::size_t>(
                                      run.cores, std::max<std::size_t>(1, s.tests.size())));
  run.threads = o.threads > 0 ? o.threads : std::max(1, static_cast<int>(run.cores) / run.parallel);
  run.material = fs::absolute(s.material_file).string();
  fs::create_directories(out.staged("specimens"));
  fs::create_directories(out.staged("tests"));
  fs::create_directories(out.staged("logs"));
  const std::map<std::string, std::string> specimen_of = run.make_specimens();
  const std::vector<Job> jobs = run.run_tests(specimen_of);
  SuiteSummary sum;
  for (std::size_t k = 0; k < s.tests.size(); ++k)
    sum.add(s.tests[k], jobs[k], out);
  const nlohmann::json props = sum.properties();
  const int parallel = run.parallel, threads = run.threads;
  nlohmann::json summary{
      {"suite", s.name},
      {"suite_file", s.file},
      {"suite_hash", s.text_hash},
      {"material", s.material.value("name", "")},
      {"material_file", s.material_file},
      {"units", "SI (m, kg, s, N, Pa, J); stresses compression positive"},
      {"properties", props},
      {"methods",
       {{"crack_initiation_over_ucs",
         "crack volumetric strain (Martin & Chandler 1994), as laboratory cores "
         "are read; crack_initiation_count_over_ucs: the crack count onset"},
        {"bts_Pa",
         "the largest load before the disk lost the tension across its loaded diameter"}}},
      {"warnings", sum.warnings},
      {"tests", sum.tests},
      {"parallel_processes", parallel},
      {"threads_per_process", threads},
      {"rocklab_version", ROCKLAB_VERSION},
      {"wall_time_s", std::chrono::duration<double>(clock::now() - t0).count()}};
  auto cell = [](const nlohmann::json& v) {
    return v.is_number() ? format_double(v.get<double>()) : std::string();
  };
  const std::vector<std::string> columns = summary_columns();
  std::string scsv = "material";
  for (const std::string& k : columns)
    scsv.append(",").append(k);
  scsv.append("\n").append(summary["material"].get<std::string>());
  for (const std::string& k : columns)
    scsv.append(",").append(cell(props.value(k, nlohmann::json())));
  scsv += "\n";
  write_text_file(out.staged("summary.json"), summary.dump(2) + "\n");
  write_text_file(out.staged("summary.csv"), scsv);
  write_text_file(out.staged("tests.csv"), sum.csv);
  out.commit();
  if (sum.failed)
    summary["failed"] = true;
  return summary;
}

std::string summary_table(const nlohmann::json& sm) {
  std::string t;
  char line[256];
  std::snprintf(line, sizeof line, "suite %s   material %s\n",
                sm["suite"].get<std::string>().c_str(), sm["material"].get<std::string>().c_str());
  t += line;
  t += "test                 type            conf [MPa]  E [GPa]   nu     peak [MPa]  tensile "
       "[MPa]  cracks  time [s]\n";
  auto mpa = [](const nlohmann::json& v, double scale) {
    char b[32];
    if (v.is_number())
      std::snprintf(b, sizeof b, "%.4g", v.get<double>() * scale);
    else
      std::snprintf(b, sizeof b, "-");
    return std::string(b);
  };
  for (const auto& r : sm["tests"]) {
    if (r["status"] != "ok") {
      std::snprintf(line, sizeof line, "%-20s %-15s FAILED (see logs/%s.log)\n",
                    r["name"].get<std::string>().c_str(), r["test"].get<std::string>().c_str(),
                    r["name"].get<std::string>().c_str());
      t += line;
      continue;
    }
    std::snprintf(line, sizeof line, "%-20s %-15s %-11s %-9s %-6s %-11s %-13s %-7lld %.1f\n",
                  r["name"].get<std::string>().c_str(), r["test"].get<std::string>().c_str(),
                  mpa(r["confinement_Pa"], 1e-6).c_str(), mpa(r["youngs_modulus_Pa"], 1e-9).c_str(),
                  mpa(r["poisson_ratio"], 1).c_str(), mpa(r["peak_stress_Pa"], 1e-6).c_str(),
                  mpa(r["tensile_strength_Pa"], 1e-6).c_str(),
                  static_cast<long long>(r["cracks"]["total"].get<std::int64_t>()),
                  r["wall_time_s"].get<double>());
    t += line;
  }
  const auto& p = sm["properties"];
  // A BTS only from valid disks: where every disk failed at a platen it is not measured, and
  // what those disks read is said as such.
  std::string bts = "BTS " + mpa(p["bts_Pa"], 1e-6) + " MPa";
  if (!p.value("bts_Pa", nlohmann::json()).is_number() &&
      p.value("bts_not_valid_Pa", nlohmann::json()).is_number())
    bts = "BTS not measured (no valid disk; the disks not valid read " +
          mpa(p["bts_not_valid_Pa"], 1e-6) + " MPa)";
  std::snprintf(line, sizeof line,
                "E %s GPa   nu %s   UCS %s MPa   %s   direct tension %s MPa   UCS/BTS %s\n",
                mpa(p["youngs_modulus_Pa"], 1e-9).c_str(), mpa(p["poisson_ratio"], 1).c_str(),
                mpa(p["ucs_Pa"], 1e-6).c_str(), bts.c_str(),
                mpa(p["direct_tension_Pa"], 1e-6).c_str(), mpa(p["ucs_over_bts"], 1).c_str());
  t += line;
  // The envelope line only where compression peaks at two confinements or more gave one; a
  // suite without triaxial tests says so instead of a row of dashes.
  const int envelope_points = p.value("envelope_points", 0);
  if (envelope_points < 2)
    std::snprintf(line, sizeof line,
                  "Envelope: none (%d compression peak%s; Mohr-Coulomb needs 2 confinements, "
                  "Hoek-Brown 3)\n",
                  envelope_points, envelope_points == 1 ? "" : "s");
  else
    std::snprintf(line, sizeof line,
                  "Mohr-Coulomb: friction angle %s deg, cohesion %s MPa (R2 %s)   Hoek-Brown m_i "
                  "%s (%d points, sigma3 up to %s UCS, fit error %s)\n",
                  mpa(p["friction_angle_deg"], 1).c_str(), mpa(p["cohesion_Pa"], 1e-6).c_str(),
                  mpa(p["mohr_coulomb_r2"], 1).c_str(), mpa(p["hoek_brown_mi"], 1).c_str(),
                  envelope_points,
                  mpa(p.value("envelope_sigma3_max_over_ucs", nlohmann::json()), 1).c_str(),
                  mpa(p.value("hoek_brown_fit_error", nlohmann::json()), 1).c_str());
  t += line;
  // Every other property a test declares (a new test's shows here without editing this table).
  const std::set<std::string> printed(std::begin(kHeadline), std::end(kHeadline));
  std::string more;
  for (const std::string& name : declared_properties())
    if (!printed.count(name))
      more.append(more.empty() ? "" : "   ")
          .append(name)
          .append(" ")
          .append(mpa(p.value(name, nlohmann::json()), 1));
  if (!more.empty())
    t += more + "\n";
  for (const auto& w : sm.value("warnings", nlohmann::json::array()))
    t += "warning: " + w.get<std::string>() + "\n";
  return t;
}

} // namespace rocklab
