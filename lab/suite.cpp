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
  s.name = read_header(top, fs::path(path).stem().string()).name;
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

// The per-test columns of tests.csv, summary.json's test rows and the printed table: every
// results.json key a frame test declares for them (lab/property.hpp).
std::vector<SuiteProperty> test_columns() {
  std::vector<SuiteProperty> out;
  for (const DeclaredProperty& d : declared_result_columns())
    out.push_back(d.p);
  return out;
}

// The declared properties in the order a suite shows them: the headline ones by their place, then
// the others in table order.
std::vector<SuiteProperty> shown_properties() {
  std::vector<SuiteProperty> out;
  for (const DeclaredProperty& d : declared_properties())
    out.push_back(d.p);
  std::stable_sort(out.begin(), out.end(), [](const SuiteProperty& a, const SuiteProperty& b) {
    const int ka = a.headline > 0 ? a.headline : 1 << 20,
              kb = b.headline > 0 ? b.headline : 1 << 20;
    return ka < kb;
  });
  return out;
}

// 3. The summary of the tests' results.
struct SuiteSummary {
  nlohmann::json tests = nlohmann::json::array();
  SuiteValues values; ///< what each test's results gave (the tests' own add_to_suite)
  nlohmann::json warnings = nlohmann::json::array(); ///< every test's, as "NAME: what"
  bool failed = false;
  std::string csv = csv_header();

  void add(const SuiteTest& t, const Job& j, OutputDir& out);
  nlohmann::json properties() const;
  static std::string csv_header();
};

std::string SuiteSummary::csv_header() {
  std::string h;
  for (const std::string& c : tests_csv_columns())
    h.append(h.empty() ? "" : ",").append(c);
  return h + "\n";
}

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
    csv += t.name + "," + row["test"].get<std::string>() + ",failed" +
           std::string(test_columns().size() + 4, ',') + "," + format_double(j.seconds) + "\n";
    return;
  }
  for (const auto& entry : fs::directory_iterator(dir / "out"))
    fs::rename(entry.path(), dir / entry.path().filename());
  fs::remove(dir / "out");
  const nlohmann::json r = read_json_file((dir / "results.json").string(), Nulls::Allow);
  row["status"] = "ok";
  row["results"] = "tests/" + t.name + "/results.json";
  for (const SuiteProperty& c : test_columns())
    row[c.name] = number_or_null(num(r, c.name));
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
  csv += t.name + "," + type + ",ok";
  for (const SuiteProperty& c : test_columns()) {
    const double v = num(r, c.name);
    csv += "," + (std::isfinite(v) ? format_double(v) : std::string());
  }
  csv += "," + r["cracks"]["tension"].dump() + "," + r["cracks"]["shear"].dump() + "," +
         r["provenance"]["grains"].dump() + "," + r["provenance"]["steps"].dump() + "," +
         format_double(j.seconds) + "\n";
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

std::vector<std::string> tests_csv_columns() {
  std::vector<std::string> cols{"name", "test", "status"};
  for (const SuiteProperty& c : test_columns())
    cols.emplace_back(c.name);
  cols.insert(cols.end(), {"cracks_tension", "cracks_shear", "grains", "steps", "wall_time_s"});
  return cols;
}

std::vector<std::string> summary_columns() {
  std::vector<std::string> cols;
  for (const SuiteProperty& p : shown_properties())
    cols.emplace_back(p.name);
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

namespace {

// How the properties that say so are measured (summary.json "methods").
nlohmann::json methods() {
  nlohmann::json m = nlohmann::json::object();
  for (const DeclaredProperty& d : declared_properties())
    if (d.p.method)
      m[d.p.name] = d.p.method;
  return m;
}

} // namespace

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
  nlohmann::json summary{{"suite", s.name},
                         {"suite_file", s.file},
                         {"suite_hash", s.text_hash},
                         {"material", s.material.value("name", "")},
                         {"material_file", s.material_file},
                         {"units", "SI (m, kg, s, N, Pa, J); stresses compression positive"},
                         {"properties", props},
                         {"methods", methods()},
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

namespace {

// `items` joined by three spaces, in lines of at most about 100 columns.
std::string wrapped(const std::vector<std::string>& items) {
  std::string out, line;
  for (const std::string& item : items) {
    if (!line.empty() && line.size() + 3 + item.size() > 100) {
      out += line + "\n";
      line.clear();
    }
    line += (line.empty() ? "" : "   ") + item;
  }
  return line.empty() ? out : out + line + "\n";
}

// The per-test table: one row per test, a column per declared result key.
std::string tests_table(const nlohmann::json& sm) {
  std::vector<std::string> head{"test", "type"};
  for (const SuiteProperty& c : test_columns()) {
    const std::string unit = display_unit(c.kind);
    head.push_back(std::string(c.label ? c.label : c.name) +
                   (unit.empty() ? "" : " [" + unit + "]"));
  }
  head.insert(head.end(), {"cracks", "time [s]"});
  std::vector<std::vector<std::string>> rows{head};
  for (const auto& r : sm["tests"]) {
    std::vector<std::string> row{r["name"].get<std::string>(), r["test"].get<std::string>()};
    if (r["status"] != "ok") {
      row.push_back("FAILED (see logs/" + row[0] + ".log)");
      rows.push_back(row);
      continue;
    }
    for (const SuiteProperty& c : test_columns()) {
      const std::string v = format_property(r.value(c.name, nlohmann::json()), c.kind);
      const std::string unit = display_unit(c.kind);
      row.push_back(v == "-" || unit.empty() ? v : v.substr(0, v.size() - unit.size() - 1));
    }
    char b[48];
    std::snprintf(b, sizeof b, "%.1f", r["wall_time_s"].get<double>());
    row.insert(row.end(), {r["cracks"]["total"].dump(), b});
    rows.push_back(row);
  }
  std::vector<std::size_t> width(head.size(), 0);
  for (const auto& row : rows) // a failed test's row runs on in its third column
    for (std::size_t k = 0; k < row.size() && row.size() == head.size(); ++k)
      width[k] = std::max(width[k], row[k].size());
  std::string t;
  for (const auto& row : rows) {
    std::string line;
    for (std::size_t k = 0; k < row.size(); ++k)
      line += k + 1 < row.size() ? row[k] + std::string(width[k] + 2 - row[k].size(), ' ') : row[k];
    t += line + "\n";
  }
  return t;
}

} // namespace

std::string summary_table(const nlohmann::json& sm) {
  std::string t = "suite " + sm["suite"].get<std::string>() + "   material " +
                  sm["material"].get<std::string>() + "\n" + tests_table(sm);
  // The headline properties first, then every other property a test declares (a new test's
  // shows here without editing this table); each says what it lacks where it was not measured.
  const nlohmann::json& p = sm["properties"];
  std::vector<std::string> headline, more;
  for (const SuiteProperty& d : shown_properties())
    (d.headline > 0 ? headline : more).push_back(property_text(d, p));
  t += wrapped(headline) + wrapped(more);
  for (const auto& w : sm.value("warnings", nlohmann::json::array()))
    t += "warning: " + w.get<std::string>() + "\n";
  return t;
}

} // namespace rocklab
