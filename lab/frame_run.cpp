#include "lab/frame_run.hpp"

#include "io/json_input.hpp"
#include "io/output_dir.hpp"
#include "io/progress.hpp"
#include "io/results.hpp"
#include "io/specimen.hpp"
#include "lab/ae_report.hpp"
#include "lab/frame/frame_test.hpp"
#include "lab/frame_snapshot.hpp"
#include "lab/protocol_table.hpp"
#include "materials/genesis.hpp"
#include "viz/svg_plots.hpp"
#include "viz/svg_png.hpp"
#include "viz/vtk_output.hpp"

#include <omp.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <numbers>

namespace rocklab {

namespace fs = std::filesystem;

SpecimenSource obtain_specimen(const Protocol& p, const std::atomic<bool>* interrupt,
                               bool progress) {
  SpecimenSource src;
  if (!p.specimen_file.empty()) {
    src.model =
        named_by(p.file, "specimen.file", [&] { return load_model(p.specimen_file, &src.meta); });
    return src;
  }
  MaterialCard card =
      named_by(p.file, "specimen.material", [&] { return load_material_card(p.material_file); });
  GenesisResult g = genesis_with_overrides(
      card, {{p.shape, p.file, "specimen.shape"}, {p.cut, p.file, "specimen.cut"}, p.seed},
      progress, interrupt);
  src.meta = specimen_meta(card, g.report);
  src.model = std::move(g.model);
  return src;
}

namespace {

/// The test's state in one line: phase, axial strain and stress, peak, cracks. The fraction done
/// is known with a strain limit (strain / limit) and after the peak (the drop toward the stop
/// rule's post_peak_fraction); before the peak of a test without a limit there is no honest ETA.
void show_progress(ProgressLine& line, const LoadingFrame& f) {
  const LabSample& c = f.current();
  const Protocol& p = f.protocol();
  const double peak = f.peak().load;
  double frac = -1;
  if (p.strain_limit > 0)
    frac = c.axial_strain / p.strain_limit;
  if (peak > 0 && c.load < 0.99 * peak && p.post_peak_fraction < 1) // past the peak
    frac = std::max(frac, (peak - c.load) / ((1 - p.post_peak_fraction) * peak));
  char buf[160];
  std::snprintf(buf, sizeof buf, "%s  strain %.3g%%  %.4g MPa (peak %.4g)  cracks %lld",
                f.phase_name(), 100 * c.axial_strain, c.axial_stress / 1e6, f.peak().stress / 1e6,
                static_cast<long long>(f.cracks().total()));
  line.show(buf, frac);
}

/// A test in progress: the model, the frame around it, the ParaView series and the checkpoint.
struct FrameRun {
  FrameRun(const Protocol& protocol, const LabOptions& options, OutputDir& dir, LabSummary& summary,
           std::string checkpoint_path)
      : p(protocol), o(options), out(dir), sum(summary), checkpoint(std::move(checkpoint_path)) {}

  const Protocol& p;
  const LabOptions& o;
  OutputDir& out;
  LabSummary& sum;
  std::string checkpoint;
  std::unique_ptr<Model> model;
  nlohmann::json meta;
  std::unique_ptr<LoadingFrame> frame;
  std::unique_ptr<VtkSeries> vtk;
  Snapshot peak_snap;
  bool have_peak_snap = false;

  void start(FrameTest& test);
  void resume(FrameTest& test);
  void write_checkpoint();
  bool loop(); ///< false: interrupted
  void write_outputs(const FrameTest& test, std::chrono::steady_clock::time_point t0);
};

void FrameRun::start(FrameTest& test) {
  vtk = std::make_unique<VtkSeries>(out.staged("vtk"));
  if (!o.resume_path.empty()) {
    resume(test);
    return;
  }
  SpecimenSource src = obtain_specimen(p, o.interrupt, o.progress);
  model = std::move(src.model);
  meta = std::move(src.meta);
  if (!p.material_file.empty()) {
    save_model(*model, out.staged("specimen.rlspec").string(), meta);
    sum.files.push_back("specimen.rlspec");
  }
  frame = std::make_unique<LoadingFrame>(p, test, *model, meta);
  frame->setup();
}

void FrameRun::resume(FrameTest& test) {
  nlohmann::json cmeta;
  model = load_model(o.resume_path, &cmeta);
  if (!cmeta.contains("lab") || !cmeta["lab"].contains("machine"))
    throw InputError(o.resume_path + ": not a rocklab test checkpoint");
  const nlohmann::json& lab = cmeta["lab"];
  if (lab.value("protocol_hash", "") != p.text_hash)
    throw InputError(o.resume_path +
                     ": the checkpoint belongs to another protocol (key "
                     "'protocol_hash' differs from " +
                     p.file + ")");
  try {
    meta = lab.at("specimen_meta");
    vtk->set_times(lab.at("vtk_times").get<std::vector<double>>());
    vtk->set_tagged(lab.at("vtk_tagged").get<std::map<std::string, double>>());
    sum.files = lab.at("files").get<std::vector<std::string>>();
  } catch (const nlohmann::json::exception&) {
    throw InputError(o.resume_path + ": corrupt checkpoint (its 'lab' record)");
  }
  // Files written before the checkpoint (specimen, snapshots) were saved beside it.
  const fs::path saved = o.resume_path + ".files";
  if (fs::exists(saved))
    fs::copy(saved, out.staged(""),
             fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  frame = std::make_unique<LoadingFrame>(p, test, *model, meta);
  frame->restore(lab["machine"], o.resume_path);
}

void FrameRun::write_checkpoint() {
  // A peak snapshot still in memory goes into the series now, so a resumed run has it too.
  if (have_peak_snap) {
    vtk->write(peak_snap, "peak");
    have_peak_snap = false;
  }
  nlohmann::json cmeta = {{"lab",
                           {{"protocol_file", p.file},
                            {"protocol_hash", p.text_hash},
                            {"specimen_meta", meta},
                            {"machine", frame->state()},
                            {"vtk_times", vtk->times()},
                            {"vtk_tagged", vtk->tagged()},
                            {"files", sum.files}}}};
  // The files written so far are kept beside the checkpoint (a copy of the staging folder). A
  // checkpoint that cannot be written (disk full) leaves the last complete one as it was.
  const fs::path files = checkpoint + ".files";
  const fs::path tmp = checkpoint + ".files.partial";
  const fs::path pending = checkpoint + ".pending";
  std::error_code ec;
  try {
    fs::remove_all(tmp, ec);
    fs::create_directories(tmp);
    fs::copy(out.staged(""), tmp, fs::copy_options::recursive);
    save_model(*model, pending.string(), cmeta);
  } catch (const std::exception& e) {
    fs::remove_all(tmp, ec);
    fs::remove(pending, ec);
    throw OutputError(checkpoint + ": cannot write the checkpoint (" + e.what() +
                      "); the last complete checkpoint, if any, is kept");
  }
  fs::remove_all(files, ec);
  fs::rename(tmp, files);
  fs::rename(pending, checkpoint);
}

bool FrameRun::loop() {
  LoadingFrame& f = *frame;
  ProgressLine progress("test", o.progress);
  while (!f.done()) {
    f.advance();
    if (f.snapshot_due()) {
      if (p.vtk)
        vtk->write(frame_snapshot(f));
      f.snapshot_taken();
    }
    if (f.peak_snapshot_due()) {
      peak_snap = frame_snapshot(f);
      have_peak_snap = true;
      f.peak_snapshot_taken();
    }
    if (o.checkpoint_every > 0 && model->step() % o.checkpoint_every == 0)
      write_checkpoint();
    if (o.interrupt && o.interrupt->load()) {
      if (o.checkpoint_every > 0)
        write_checkpoint();
      return false; // OUTDIR is left untouched (the staging folder goes away)
    }
    if (model->step() % 64 == 0 && progress.due())
      show_progress(progress, f);
  }
  return true;
}

/// The SVG documents of a test: the stress-strain plot with crack counts, and the crack map of
/// the final state (made while the model exists; rendered and written after it is freed).
struct PlotDocuments {
  std::string stress_strain, crack_map;
  std::string magnitude_frequency, acoustic_emission; ///< "" without moment tensors
};

LoadCurve load_curve(const LoadingFrame& f, const PlotLabels& labels) {
  LoadCurve c{{}, {}, {}, labels.curve, labels.x, labels.y};
  for (const LabSample& s : f.samples()) {
    c.time.push_back(s.time);
    c.strain_pct.push_back(100 * s.axial_strain);
    c.stress_mpa.push_back(1e-6 * s.axial_stress);
  }
  return c;
}

PlotDocuments plot_documents(const FrameTest& test, const LoadingFrame& f,
                             const nlohmann::json& meta, const nlohmann::json& r,
                             const EventClustering& ev) {
  const PlotLabels labels = test.plot_labels();
  PlotSeries axial{labels.curve, {}, {}, "#000000"};
  PlotSeries lateral{"axial stress vs lateral strain", {}, {}, "#7f7f7f", true};
  PlotSeries volumetric{"axial stress vs volumetric strain", {}, {}, "#2ca02c", true};
  PlotSeries ct{"tensile cracks", {}, {}, "#d62728", false, true};
  PlotSeries cs{"shear cracks", {}, {}, "#1f3fbf", false, true};
  std::size_t crack_i = 0;
  std::int64_t nt = 0, ns = 0;
  const auto& cracks = f.cracks().cracks();
  for (const LabSample& s : f.samples()) {
    while (crack_i < cracks.size() && cracks[crack_i].step <= s.step)
      (cracks[crack_i++].mode == 1 ? nt : ns) += 1;
    axial.x.push_back(100 * s.axial_strain);
    axial.y.push_back(1e-6 * s.axial_stress);
    ct.x.push_back(100 * s.axial_strain);
    ct.y.push_back(static_cast<double>(nt));
    cs.x.push_back(100 * s.axial_strain);
    cs.y.push_back(static_cast<double>(ns));
    if (labels.lateral) {
      lateral.x.push_back(100 * s.lateral_strain);
      lateral.y.push_back(1e-6 * s.axial_stress);
      volumetric.x.push_back(100 *
                             (s.axial_strain + (f.geometry().dim == 2 ? 1 : 2) * s.lateral_strain));
      volumetric.y.push_back(1e-6 * s.axial_stress);
    }
  }
  std::vector<PlotSeries> series; // moved in: a 10k-grain test's five series hold ~3 MB
  series.push_back(std::move(axial));
  if (!lateral.x.empty()) {
    series.push_back(std::move(lateral));
    series.push_back(std::move(volumetric));
  }
  series.push_back(std::move(ct));
  series.push_back(std::move(cs));
  const std::string title =
      std::string(test.name()) + " test: " + meta.value("material_name", std::string("specimen"));
  Snapshot final = frame_snapshot(f);
  add_fractures(final, f.cracks().cracks(), ev, INFINITY);
  std::vector<PlotMarker> markers; // the test's own: crack stresses, a disk's strength
  test.plot_markers(f.samples(), r, markers);
  return {
      line_plot_svg(title, labels.x, labels.y, "cracks", series, markers),
      crack_map_svg(final, title + ", cracks at the end", labels.map_axis, f.geometry().diametral),
      magnitude_frequency_svg(ev.events, title + ", magnitude-frequency of the acoustic emission"),
      acoustic_emission_svg(load_curve(f, labels), ev.events, title)};
}

void FrameRun::write_outputs(const FrameTest& test, std::chrono::steady_clock::time_point t0) {
  const LoadingFrame& f = *frame;
  model->release_scratch(); // the run is over: its detection scratch is not needed
  // The final snapshot, and the latest peak snapshot (as the "peak" files, placed in the .pvd by
  // its time; a checkpoint may have written an earlier one already).
  if (p.vtk) {
    if (have_peak_snap)
      vtk->write(peak_snap, "peak");
    vtk->write(frame_snapshot(f));
  }
  nlohmann::json r = f.results();
  const EventClustering ev = fracture_events(f, p, r);
  if (p.vtk) {
    const CellSummary cells = vtk->write_fractures(
        [&](double t) {
          Snapshot s;
          s.dim = f.model().settings.dim;
          s.outline.round = f.geometry().round || f.geometry().diametral;
          add_fractures(s, f.cracks().cracks(), ev, t);
          return s;
        },
        p.cells);
    if (p.cells)
      r["power_cells"] = {{"grains", cells.grains},
                          {"hidden_grains", cells.hidden},
                          {"volume_sum_m3", cells.volume_sum},
                          {"clip_shape_volume_m3", cells.shape_volume},
                          {"specimen_volume_m3", f.current_volume()},
                          {"contact_cracks", cells.contact_cracks},
                          {"contact_cracks_as_faces", cells.faced_cracks}};
    for (const std::string& name : vtk->write_collections())
      sum.files.push_back("vtk/" + name);
  }
  sum.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r["protocol"] = p.file;
  r["provenance"] = {{"rocklab_version", ROCKLAB_VERSION},
                     {"test_revision", test.revision()},
                     {"material", meta.value("material_name", "")},
                     {"material_file", meta.value("material_file", "")},
                     {"material_hash", meta.value("material_hash", "")},
                     {"seed", meta.value("seed", std::uint64_t{0})},
                     {"specimen_file", p.specimen_file},
                     {"protocol_hash", p.text_hash},
                     {"grains", model->balls.size()},
                     {"steps", model->step()},
                     {"model_time_s", model->time()},
                     {"threads", omp_get_max_threads()},
                     {"wall_time_s", sum.wall_seconds}};
  write_file(out.staged("history.csv"), [&](std::ostream& o) { f.write_history_csv(o); });
  write_file(out.staged("cracks.csv"), [&](std::ostream& o) { f.cracks().write_csv(o); });
  write_file(out.staged("events.csv"), [&](std::ostream& o) { write_events_csv(o, ev.events); });
  sum.files.insert(sum.files.end(), {"results.json", "history.csv", "cracks.csv", "events.csv"});
  PlotDocuments plots;
  if (p.plots)
    plots = plot_documents(test, f, meta, r, ev);
  // The run's state is not needed any more: freed before the PNGs are rendered (a 10k-grain
  // flat-jointed model holds about 35 MB, the renderer takes about 16 MB).
  peak_snap = Snapshot{};
  vtk.reset();
  frame.reset();
  model.reset();
  if (p.plots) {
    for (const auto& [svg, png] :
         {write_svg_and_png(out.staged("stress_strain.svg"), plots.stress_strain),
          write_svg_and_png(out.staged("crack_map.svg"), plots.crack_map)})
      sum.files.insert(sum.files.end(), {svg, png});
    for (const auto& [name, doc] : {std::pair<std::string, const std::string*>{
                                        "magnitude_frequency.svg", &plots.magnitude_frequency},
                                    {"acoustic_emission.svg", &plots.acoustic_emission}})
      if (!doc->empty()) {
        const auto [svg, png] = write_svg_and_png(out.staged(name), *doc);
        sum.files.insert(sum.files.end(), {svg, png});
      }
  }
  r["files"] = sum.files;
  sum.results = r;
  write_text_file(out.staged("results.json"), r.dump(2) + "\n");
}

} // namespace

LabSummary run_frame_test(FrameTest& test, const Protocol& p, const LabOptions& o) {
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  LabSummary sum;
  OutputDir out(o.out_dir);
  FrameRun run{p, o, out, sum,
               o.checkpoint_path.empty() ? o.out_dir + ".checkpoint" : o.checkpoint_path};
  run.start(test);
  if (!run.loop()) {
    sum.interrupted = true;
    return sum;
  }
  run.write_outputs(test, t0);
  out.commit();
  // A finished run needs no checkpoint.
  std::error_code ec;
  if (o.checkpoint_every > 0 || !o.resume_path.empty()) {
    fs::remove(run.checkpoint, ec);
    fs::remove_all(run.checkpoint + ".files", ec);
  }
  return sum;
}

LabSummary run_lab_test(const Protocol& p, const LabOptions& o) {
  return run_frame_test(*p.frame_test, p, o); // the test that read the protocol's options
}

LabSummary FrameTest::run(const nlohmann::json&, const std::string& file, const LabOptions& o) {
  // One test object per run: this one reads the protocol's options, runs and prints (a second
  // one made from the file again used to run it).
  return run_lab_test(
      load_protocol(file, std::shared_ptr<FrameTest>(std::shared_ptr<FrameTest>(), this)), o);
}

void FrameTest::print(const LabSummary& s, const std::string& out_dir) const {
  const nlohmann::json& r = s.results;
  std::printf("test         %s   material %s   grains %lld   steps %lld\n",
              r["test"].get<std::string>().c_str(),
              r["provenance"]["material"].get<std::string>().c_str(),
              static_cast<long long>(r["provenance"]["grains"].get<std::int64_t>()),
              static_cast<long long>(r["provenance"]["steps"].get<std::int64_t>()));
  print_results(r);
  const auto& c = r["cracks"];
  std::printf("cracks       %lld tension, %lld shear (%lld at peak)\n",
              static_cast<long long>(c["tension"].get<std::int64_t>()),
              static_cast<long long>(c["shear"].get<std::int64_t>()),
              static_cast<long long>(c["at_peak"]["total"].get<std::int64_t>()));
  if (r.contains("fracture_events")) {
    const auto& e = r["fracture_events"];
    std::printf("fractures    %zu broken contacts in %zu events (largest %zu cracks)\n",
                e["broken_contacts"].get<std::size_t>(), e["count"].get<std::size_t>(),
                e["largest_event_cracks"].get<std::size_t>());
  }
  if (r.contains("acoustic_emission"))
    print_acoustic_emission(r["acoustic_emission"]);
  std::printf("stopped      %s\n", r["stop_reason"].get<std::string>().c_str());
  std::printf("wall time    %.1f s on %d thread(s)\n", s.wall_seconds, omp_get_max_threads());
  std::printf("results      %s/results.json  %s/history.csv  %s/cracks.csv  %s/events.csv\n",
              out_dir.c_str(), out_dir.c_str(), out_dir.c_str(), out_dir.c_str());
  for (const auto& f : r["files"]) {
    const std::string name = f.get<std::string>();
    if (name.ends_with(".svg"))
      std::printf("plot         %s/%s (and .png)\n", out_dir.c_str(), name.c_str());
    else if (name == "vtk/grains.pvd")
      std::printf("ParaView     %s/vtk/grains.pvd (also cells, contact_cracks, events, bonds, "
                  "cracks, walls; pvpython viz/rocklab_paraview.py %s [--section] sets up the "
                  "view)\n",
                  out_dir.c_str(), out_dir.c_str());
  }
}

} // namespace rocklab
