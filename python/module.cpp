// rocklab._rocklab: the command line's commands in-process, for the Python package rocklab
// (python/rocklab/__init__.py turns paths and dicts into the (name, text) pairs taken here and the
// files written into dicts and NumPy arrays). Every input is a name and, for a dict given in
// Python, its JSON text: the text is read as if it were the file `name` (io/json_input.hpp
// InputText), so errors name it and relative paths in it resolve against its folder. Bad input
// raises ValueError with the message `rocklab` prints before exiting with status 2, a physical
// blow-up rocklab.PhysicsError (status 3), an unwritable output OSError (status 4). All
// quantities SI.
#include "io/json_input.hpp"
#include "io/output_dir.hpp"
#include "io/scene.hpp"
#include "io/scene_run.hpp"
#include "io/specimen.hpp"
#include "lab/calibration/calibration_file.hpp"
#include "lab/calibration/campaign.hpp"
#include "lab/protocol_table.hpp"
#include "lab/suite.hpp"
#include "materials/genesis.hpp"
#include "released_call.hpp"

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

namespace py = pybind11;
using nlohmann::json;

namespace rocklab::python {
namespace {

// A specimen made or read in Python: the model and what its file carries.
struct Specimen {
  std::shared_ptr<Model> model;
  json meta;   ///< the specimen file's metadata (card, seed, genesis report without its time)
  json report; ///< the genesis report (SPECIMEN.report.json), null when the file had none

  void save(const std::string& path) const { save_specimen(*model, path, meta, report); }
};

// While it lives, `name` reads as `text` on this thread when text is given (a dict in Python).
struct MaybeText {
  std::optional<InputText> text;
  MaybeText(const std::string& name, const std::optional<std::string>& t) {
    if (t)
      text.emplace(name, *t);
  }
};

// The command's own error for a blow-up names its input, as `rocklab` prints it.
template <class F> auto naming_input(const std::string& name, F&& f) {
  try {
    return f();
  } catch (const PhysicsError& e) {
    throw PhysicsError(name + ": " + e.what());
  }
}

std::shared_ptr<Specimen> genesis(const std::string& name, const std::optional<std::string>& text,
                                  const std::string& overrides_json, std::int64_t seed, int threads,
                                  const py::object& progress) {
  const bool show = !progress.is_none();
  return released_call<std::shared_ptr<Specimen>>(
      progress, threads, [&](const std::atomic<bool>* stop) {
        const MaybeText given(name, text);
        std::optional<InputText> patched;
        const json overrides = json::parse(overrides_json);
        if (!overrides.empty()) {
          std::vector<std::pair<std::string, json>> list;
          for (const auto& [key, value] : overrides.items())
            list.emplace_back(key, value);
          const json card = calibration::override_card(read_json_file(name), list, name);
          patched.emplace(name, card.dump(1) + "\n");
        }
        MaterialCard card = load_material_card(name);
        GenesisOverrides o{{nullptr, name, "shape"}, {nullptr, name, "cut"}, std::nullopt};
        if (seed >= 0)
          o.seed = static_cast<std::uint64_t>(seed);
        GenesisResult g =
            naming_input(name, [&] { return genesis_with_overrides(card, o, show, stop); });
        auto s = std::make_shared<Specimen>();
        s->meta = specimen_meta(card, g.report);
        s->report = g.report.to_json();
        s->model = std::move(g.model);
        return s;
      });
}

std::shared_ptr<Specimen> load_specimen(const std::string& path) {
  auto s = std::make_shared<Specimen>();
  s->model = load_model(path, &s->meta);
  if (std::filesystem::exists(path + ".report.json"))
    s->report = read_json_file(path + ".report.json", Nulls::Allow);
  return s;
}

// `rocklab test`: the results.json content as JSON text, or "" when interrupted.
// `specimen_file` (absolute; "": the protocol's own) replaces the protocol's specimen.
std::string test(const std::string& name, const std::optional<std::string>& text,
                 const std::string& specimen_file, const std::string& out_dir, int threads,
                 const py::object& progress) {
  return released_call<std::string>(progress, threads, [&](const std::atomic<bool>* stop) {
    const MaybeText given(name, text);
    json j = read_json_file(name);
    std::optional<InputText> patched; // the protocol reads its own text again (hash, checks)
    if (!specimen_file.empty()) {
      j["specimen"] = json{{"file", specimen_file}};
      patched.emplace(name, j.dump(1) + "\n");
    }
    const std::unique_ptr<LabProtocol> t = lab_protocol_of(j, name);
    LabOptions o;
    o.out_dir = out_dir;
    o.progress = !progress.is_none();
    o.interrupt = stop;
    const LabSummary s = naming_input(name, [&] { return t->run(j, name, o); });
    return s.interrupted ? std::string() : s.results.dump();
  });
}

// `rocklab run`: the run's summary (steps, model time, wall time, events) as JSON text.
std::string run(const std::string& name, const std::optional<std::string>& text,
                const std::string& out_dir, int threads, const py::object& progress) {
  return released_call<std::string>(progress, threads, [&](const std::atomic<bool>* stop) {
    const MaybeText given(name, text);
    Scene scene = load_scene(name);
    RunOptions o;
    o.out_dir = out_dir;
    o.progress = !progress.is_none();
    o.interrupt = stop;
    const RunSummary s = naming_input(name, [&] { return run_scene(scene, o); });
    return json{{"steps", s.steps},
                {"time_s", s.time},
                {"wall_time_s", s.wall_seconds},
                {"events",
                 {{"created", s.events.created},
                  {"deleted", s.events.deleted},
                  {"slip_change", s.events.slip_change},
                  {"bond_break", s.events.bond_break}}}}
        .dump();
  });
}

// `rocklab suite`: summary.json's content as JSON text.
std::string suite(const std::string& name, const std::optional<std::string>& text,
                  const std::string& out_dir, int threads, const std::string& executable,
                  const py::object& progress) {
  return released_call<std::string>(progress, 0, [&](const std::atomic<bool>* stop) {
    const MaybeText given(name, text);
    const Suite s = load_suite(name);
    SuiteOptions o;
    o.out_dir = out_dir;
    o.executable = executable;
    o.threads = threads;
    o.progress = !progress.is_none();
    o.interrupt = stop;
    return run_suite(s, o).dump();
  });
}

// `rocklab calibrate`: the campaign's outcome as JSON text (the card and report are in out_dir).
std::string calibrate(const std::string& name, const std::optional<std::string>& text,
                      const std::string& out_dir, int jobs, const std::string& executable,
                      const py::object& progress) {
  return released_call<std::string>(progress, 0, [&](const std::atomic<bool>* stop) {
    const MaybeText given(name, text);
    calibration::EvaluatorOptions o;
    o.out_dir = out_dir;
    o.executable = executable;
    o.jobs = jobs;
    o.interrupt = stop;
    o.progress = !progress.is_none();
    const calibration::CampaignSummary cs = calibration::run_campaign(name, o);
    return json{{"met", cs.outcome.met},
                {"evaluations", cs.outcome.history.size()},
                {"validation_seeds", cs.validation_seeds},
                {"validation_met", cs.validation_met},
                {"suites_run", cs.suites_run},
                {"suites_cached", cs.suites_cached},
                {"wall_time_s", cs.wall_seconds}}
        .dump();
  });
}

} // namespace
} // namespace rocklab::python

PYBIND11_MODULE(_rocklab, m) {
  using namespace rocklab::python;
  m.doc() = "rocklab's commands in-process (use the package rocklab, not this module). SI units.";
  static py::exception<rocklab::PhysicsError> physics_error(m, "PhysicsError", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p)
        std::rethrow_exception(p);
    } catch (const rocklab::InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const rocklab::PhysicsError& e) {
      physics_error(e.what());
    } catch (const rocklab::OutputError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    } catch (const std::filesystem::filesystem_error& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    }
  });
  m.attr("VERSION") = ROCKLAB_VERSION;

  py::class_<Specimen, std::shared_ptr<Specimen>>(m, "Specimen")
      .def("save", &Specimen::save, py::arg("path"), py::call_guard<py::gil_scoped_release>())
      .def_property_readonly("meta_json", [](const Specimen& s) { return s.meta.dump(); })
      .def_property_readonly("report_json", [](const Specimen& s) { return s.report.dump(); })
      .def_property_readonly("grains", [](const Specimen& s) { return s.model->balls.size(); })
      .def_property_readonly("dimension", [](const Specimen& s) { return s.model->settings.dim; });
  m.def("load_specimen", &load_specimen, py::arg("path"), py::call_guard<py::gil_scoped_release>());
  m.def("genesis", &genesis, py::arg("name"), py::arg("text"), py::arg("overrides_json"),
        py::arg("seed"), py::arg("threads"), py::arg("progress"));
  m.def("test", &test, py::arg("name"), py::arg("text"), py::arg("specimen_file"),
        py::arg("out_dir"), py::arg("threads"), py::arg("progress"));
  m.def("run", &run, py::arg("name"), py::arg("text"), py::arg("out_dir"), py::arg("threads"),
        py::arg("progress"));
  m.def("suite", &suite, py::arg("name"), py::arg("text"), py::arg("out_dir"), py::arg("threads"),
        py::arg("executable"), py::arg("progress"));
  m.def("calibrate", &calibrate, py::arg("name"), py::arg("text"), py::arg("out_dir"),
        py::arg("jobs"), py::arg("executable"), py::arg("progress"));
  m.def("lab_tests", &rocklab::lab_protocol_names);
}
