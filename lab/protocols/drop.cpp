#include "lab/protocols/drop.hpp"

#include "contact/model_json.hpp"
#include "core/model.hpp"
#include "io/json_input.hpp"
#include "io/output_dir.hpp"
#include "io/results.hpp"
#include "io/scene.hpp"
#include "lab/lab_protocol.hpp"
#include "viz/svg_plots.hpp"
#include "viz/svg_png.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

namespace rocklab {

double rocfall_restitution(double R_N, double V_half, double v) {
  return R_N / (1.0 + (v / V_half) * (v / V_half)); // Eq. 35
}

DropProtocol drop_protocol_from_json(const nlohmann::json& j, const std::string& file) {
  DropProtocol p;
  p.file = file;
  p.raw = j;
  JsonObject top(j, file, "");
  if (top.choice("test", {"drop"}) != "drop")
    top.fail("test", "expected \"drop\"");
  read_header(top, "");
  p.dim = static_cast<int>(top.integer("dimension", 2, 3, 2));
  {
    JsonObject r = top.object("rock");
    p.density = r.number("density", Range::density(), std::nullopt, "kg/m^3");
    p.rock = read_clump_pebbles(r, p.dim, false);
    if (r.has("bond")) {
      JsonObject b = r.object("bond");
      p.bonded = true;
      p.bond_model = b.choice("model", {"contactbond", "linearpbond"});
      JsonObject props = b.object("properties");
      p.bond = read_contact_props(props, p.bond_model, p.dim);
      // Template pebbles touch at a gap of round-off size: bond them.
      double rmin = std::numeric_limits<double>::infinity();
      for (const Pebble& q : p.rock)
        rmin = std::min(rmin, q.radius);
      if (auto* cb = std::get_if<ContactBondProps>(&p.bond))
        cb->bond_gap_hi = std::max(cb->bond_gap_hi, 1e-9 * rmin);
      if (auto* pb = std::get_if<LinearPBondProps>(&p.bond))
        pb->bond_gap_hi = std::max(pb->bond_gap_hi, 1e-9 * rmin);
      b.finish();
      if (p.rock.size() < 2)
        r.fail("bond", "a bonded rock needs at least two pebbles");
    }
    r.finish();
  }
  {
    JsonObject c = top.object("contact");
    p.model = c.choice("model", {"powerplastic", "hysteretic", "linear", "contactbond"});
    JsonObject props = c.object("properties");
    p.contact = read_contact_props(props, p.model, p.dim);
    c.finish();
  }
  for (const auto& [jv, path] : top.array("impact_speeds")) {
    if (!jv->is_number() || !(jv->get<double>() > 0) || jv->get<double>() > 1000)
      throw InputError(file + ": key '" + path + "': expected a speed in (0, 1000] m/s, got " +
                       describe(*jv));
    p.speeds.push_back(jv->get<double>());
  }
  if (p.speeds.empty())
    top.fail("impact_speeds", "give at least one impact speed (m/s)");
  double rmin = std::numeric_limits<double>::infinity();
  for (const Pebble& q : p.rock)
    rmin = std::min(rmin, q.radius);
  p.gravity = top.number("gravity", Range::non_negative(), 9.81, "m/s^2");
  p.release_gap = top.number("release_gap", Range::non_negative(), 0.05 * rmin, "m");
  for (double v : p.speeds)
    if (v * v < 2 * p.gravity * p.release_gap)
      top.fail("release_gap", "a rock released " + format_double(p.release_gap) +
                                  " m above the platen already hits it faster than " +
                                  format_double(v) + " m/s; lower release_gap");
  p.timestep_safety = top.number("timestep_safety", {0, 1, true, false}, 0.1);
  p.local_damping = top.number("local_damping", Range::half_open(0, 1), 0.0);
  p.max_time = top.number("max_time", Range::positive(), 0.05, "s");
  p.history_every = top.integer("history_every", 1, 10'000'000, 20);
  if (top.has("calibrate")) {
    JsonObject c = top.object("calibrate");
    p.calibrate = true;
    if (p.model != "powerplastic")
      c.fail("parameter", "calibration fits the exponent b of the \"powerplastic\" contact");
    c.choice("parameter", {"exponent"}, "exponent");
    p.R_N = c.number("R_N", {0, 1, true, true}, 0.53);
    p.V_half = c.number("V_half", Range::positive(), 9.144, "m/s");
    p.b_min = c.number("b_min", {1, 1000, false, false}, 1.0);
    p.b_max = c.number("b_max", {1, 10000, true, false}, 500.0);
    if (p.b_max <= p.b_min)
      c.fail("b_max", "must be above b_min (" + format_double(p.b_min) + ")");
    p.tolerance = c.number("tolerance", {0, 0.1, true, false}, 1e-3);
    c.finish();
  }
  {
    JsonObject o = top.optional_object("output");
    p.plots = o.boolean("plots", true);
    o.finish();
  }
  top.finish();
  return p;
}

namespace {

nlohmann::json to_json(const DropResult& r, bool calibrated) {
  nlohmann::json j{{"impact_speed_m_s", r.speed},
                   {"measured_impact_speed_m_s", r.v_impact},
                   {"rebound_normal_velocity_m_s", r.v_rebound},
                   {"rebound_tangential_speed_m_s", r.v_tangential},
                   {"rebound_spin_rad_s", r.spin},
                   {"restitution_velocity", r.e_velocity},
                   {"restitution_energy", r.e_energy},
                   {"kinetic_before_J", r.ke_before},
                   {"kinetic_after_J", r.ke_after},
                   {"kinetic_rotational_after_J", r.ke_rotational_after},
                   {"lost_J",
                    {{"plastic", r.plastic},
                     {"friction", r.slip},
                     {"dashpot", r.dashpot},
                     {"local_damping", r.damping},
                     {"bond_break", r.bond_break}}},
                   {"contact_time_s", r.contact_time},
                   {"max_platen_force_N", r.max_force},
                   {"touches", r.touches},
                   {"rebounded", r.rebounded},
                   {"steps", r.steps}};
  if (r.exponent > 0)
    j["exponent"] = r.exponent;
  if (!r.fragments.empty())
    j["fragments"] = {{"count", r.fragments.size()},
                      {"masses_kg", r.fragments},
                      {"bonds_broken", r.bonds_broken}};
  if (calibrated)
    j["target_restitution"] = r.target;
  return j;
}

} // namespace

namespace {

// The exponent b whose drop at speed v rebounds with the RocFall restitution (Eq. 35): the root
// of e(b) = target. With the elastic displacement T/kn far below the plastic one, Eq. 30 gives
// e^2 (b + 1) ~ constant: that guides the steps, inside a bracket that shrinks like bisection
// whenever the guide fails (e falls as b grows). Returns the fitted drop (with its history).
DropResult fit_exponent(const DropProtocol& p, double v, std::string& history, int& evals) {
  const double target = rocfall_restitution(p.R_N, p.V_half, v);
  double blo = p.b_min, bhi = p.b_max;
  double b = std::clamp(1.0 / (target * target) - 1.0, blo, bhi);
  DropResult r;
  evals = 0;
  for (int it = 0; it < 60; ++it) {
    r = run_drop(p, v, b);
    ++evals;
    if (std::abs(r.e_energy - target) <= p.tolerance * target)
      break;
    (r.e_energy > target ? blo : bhi) = b;
    if (bhi <= blo * (1 + 1e-12))
      break; // the target lies outside [b_min, b_max]: keep the nearest end
    double next = (b + 1) * (r.e_energy / target) * (r.e_energy / target) - 1;
    if (!(next > blo && next < bhi))
      next = std::sqrt(blo * bhi);
    b = next;
  }
  r = run_drop(p, v, r.exponent, &history); // the fitted drop again, with its history
  ++evals;
  r.target = target;
  return r;
}

nlohmann::json results_json(const DropProtocol& p, const std::vector<DropResult>& results,
                            const std::vector<int>& evaluations, double wall) {
  nlohmann::json res;
  res["units"] = "SI (m, kg, s, N, J)";
  res["test"] = "drop";
  {
    const MassProperties mp = union_mass_properties(p.rock, p.density, p.dim);
    nlohmann::json pebbles = nlohmann::json::array();
    for (const Pebble& q : p.rock)
      pebbles.push_back({{"position_m", {q.position.x(), q.position.y(), q.position.z()}},
                         {"radius_m", q.radius}});
    res["rock"] = {{"dimension", p.dim},
                   {"pebbles", pebbles},
                   {"density_kg_m3", p.density},
                   {"mass_kg", mp.mass},
                   {"mass_note", p.dim == 2 ? "per metre of thickness (unit-thickness disks)" : ""},
                   {"union_integration", mp.exact ? "exact" : "grid"}};
  }
  res["contact_model"] = p.model;
  res["contact_properties"] = p.raw["contact"]["properties"];
  res["drops"] = nlohmann::json::array();
  for (const DropResult& r : results)
    res["drops"].push_back(to_json(r, p.calibrate));
  if (p.calibrate) {
    nlohmann::json cal{{"law", "RocFall scaled normal restitution, thesis Eq. 35"},
                       {"R_N", p.R_N},
                       {"V_half_m_s", p.V_half},
                       {"fitted", "exponent b of the power-function unloading branch"},
                       {"matched", "restitution by energy (Eq. 24), total kinetic energy"}};
    double worst = 0;
    for (const DropResult& r : results) {
      const double bounce = r.e_energy * r.v_impact, want = r.target * r.v_impact;
      worst = std::max(worst, std::abs(bounce - want) / want);
    }
    cal["worst_bounce_velocity_error"] = worst;
    cal["simulations"] = evaluations;
    res["calibration"] = cal;
  }
  res["provenance"] = {
      {"rocklab_version", ROCKLAB_VERSION}, {"protocol", p.file}, {"wall_time_s", wall}};
  return res;
}

std::string restitution_csv(const DropProtocol& p, const std::vector<DropResult>& results) {
  std::string csv = "impact_speed_m_s,measured_impact_speed_m_s,rebound_normal_velocity_m_s,"
                    "restitution_velocity,restitution_energy,bounce_velocity_energy_m_s,"
                    "rebound_spin_rad_s,kinetic_before_J,kinetic_after_J,plastic_J,friction_J,"
                    "local_damping_J,bond_break_J,contact_time_s,touches,exponent,"
                    "eq35_restitution,eq35_bounce_velocity_m_s\n";
  for (const DropResult& r : results) {
    const double e35 = rocfall_restitution(p.R_N, p.V_half, r.speed);
    const double vals[] = {r.speed,
                           r.v_impact,
                           r.v_rebound,
                           r.e_velocity,
                           r.e_energy,
                           r.e_energy * r.v_impact,
                           r.spin,
                           r.ke_before,
                           r.ke_after,
                           r.plastic,
                           r.slip,
                           r.damping,
                           r.bond_break,
                           r.contact_time,
                           static_cast<double>(r.touches),
                           r.exponent,
                           e35,
                           e35 * r.speed};
    for (std::size_t k = 0; k < std::size(vals); ++k) {
      if (k)
        csv += ',';
      csv += format_double(vals[k]);
    }
    csv += '\n';
  }
  return csv;
}

void write_drop_plots(const DropProtocol& p, const std::vector<DropResult>& results, OutputDir& out,
                      nlohmann::json& files) {
  PlotSeries measured{"bounce velocity sqrt(KE after/KE before) x v", {}, {}, "#d62728"};
  PlotSeries by_velocity{"normal rebound velocity", {}, {}, "#1f77b4", true};
  PlotSeries law{"RocFall Eq. 35 (R_N " + format_double(p.R_N) + ", V0.5 " +
                     format_double(p.V_half) + " m/s)",
                 {},
                 {},
                 "#2ca02c",
                 true};
  for (const DropResult& r : results) {
    measured.x.push_back(r.speed);
    measured.y.push_back(r.e_energy * r.v_impact);
    by_velocity.x.push_back(r.speed);
    by_velocity.y.push_back(r.v_rebound);
  }
  const double vmax = *std::max_element(p.speeds.begin(), p.speeds.end());
  for (int k = 0; k <= 100; ++k) {
    const double v = vmax * k / 100.0;
    law.x.push_back(v);
    law.y.push_back(rocfall_restitution(p.R_N, p.V_half, v) * v);
  }
  const auto [svg, png] = write_svg_and_png(
      out.staged("restitution.svg"),
      line_plot_svg("drop test: bounce velocity vs impact velocity", "impact velocity [m/s]",
                    "bounce velocity [m/s]", "", {measured, by_velocity, law}));
  files.insert(files.end(), {svg, png});
  if (p.calibrate) {
    PlotSeries fitted{"fitted exponent b", {}, {}, "#d62728"};
    PlotSeries eq36{"thesis Eq. 36 (kn 6.4e10 N/m)", {}, {}, "#7f7f7f", true};
    for (const DropResult& r : results) {
      fitted.x.push_back(r.speed);
      fitted.y.push_back(r.exponent);
    }
    for (int k = 0; k <= 100; ++k) {
      const double v = 1 + (vmax - 1) * k / 100.0;
      eq36.x.push_back(v);
      eq36.y.push_back(0.0429 * v * v * v - 0.4744 * v * v + 2.5508 * v + 1.1489); // Eq. 36
    }
    const auto [esvg, epng] = write_svg_and_png(
        out.staged("exponent.svg"),
        line_plot_svg("power-function exponent fitted to Eq. 35", "impact velocity [m/s]",
                      "exponent b [-]", "", {fitted, eq36}));
    files.insert(files.end(), {esvg, epng});
  }
}

} // namespace

nlohmann::json run_drop_test(const DropProtocol& p, const std::string& out_dir, bool progress,
                             const std::atomic<bool>* interrupt) {
  const auto t0 = std::chrono::steady_clock::now();
  OutputDir out(out_dir);
  check_estimate(drop_estimate(p), p.file, "impact_speeds", !progress);
  std::string history = "impact_speed_m_s,time_s,step,kinetic_J,kinetic_rotational_J,strain_J,"
                        "plastic_J,friction_J,body_work_J,height_m,normal_velocity_m_s\n";
  std::vector<DropResult> results;
  std::vector<int> evaluations;
  for (double v : p.speeds) {
    if (interrupt && interrupt->load())
      throw std::runtime_error("interrupted; nothing was written");
    int evals = 1;
    const DropResult r =
        p.calibrate ? fit_exponent(p, v, history, evals) : run_drop(p, v, 0, &history);
    results.push_back(r);
    evaluations.push_back(evals);
    if (progress)
      std::fprintf(stderr, "[rocklab drop] %.3g m/s: e_v %.4f e_E %.4f%s\n", v, r.e_velocity,
                   r.e_energy, p.calibrate ? (" b " + format_double(r.exponent)).c_str() : "");
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  nlohmann::json res = results_json(p, results, evaluations, wall);
  write_text_file(out.staged("restitution.csv"), restitution_csv(p, results));
  write_text_file(out.staged("history.csv"), history);
  nlohmann::json files = {"results.json", "restitution.csv", "history.csv"};
  if (p.plots)
    write_drop_plots(p, results, out, files);
  res["files"] = files;
  write_text_file(out.staged("results.json"), res.dump(2) + "\n");
  out.commit();
  return res;
}

namespace {

// The drop test as a kind of laboratory test (lab/protocol_table.cpp).
class DropTest final : public LabProtocol {
public:
  const char* name() const override { return "drop"; }
  LabSummary run(const nlohmann::json& j, const std::string& file, const LabOptions& o) override {
    if (o.checkpoint_every > 0 || !o.resume_path.empty())
      throw InputError(file + ": drop tests are short and have no checkpoints; leave out "
                              "--checkpoint-every and --resume");
    const DropProtocol p = drop_protocol_from_json(j, file);
    LabSummary s;
    s.results = run_drop_test(p, o.out_dir, o.progress, o.interrupt);
    return s;
  }
  void print(const LabSummary& s, const std::string& out_dir) const override {
    const nlohmann::json& r = s.results;
    std::printf("drop test   rock %.4g kg%s, contact %s (units SI)\n",
                r["rock"]["mass_kg"].get<double>(),
                r["rock"]["dimension"].get<int>() == 2 ? " per m thickness" : "",
                r["contact_model"].get<std::string>().c_str());
    std::printf("%8s %10s %10s %8s %8s %10s %10s %8s\n", "v [m/s]", "v_in", "v_out_n", "e_v", "e_E",
                "spin", "plastic[J]", "b");
    for (const auto& d : r["drops"])
      std::printf("%8.3g %10.4g %10.4g %8.4f %8.4f %10.4g %10.4g %8.4g\n",
                  d["impact_speed_m_s"].get<double>(), d["measured_impact_speed_m_s"].get<double>(),
                  d["rebound_normal_velocity_m_s"].get<double>(),
                  d["restitution_velocity"].get<double>(), d["restitution_energy"].get<double>(),
                  d["rebound_spin_rad_s"].get<double>(), d["lost_J"]["plastic"].get<double>(),
                  d.value("exponent", 0.0));
    if (r.contains("calibration"))
      std::printf("calibration  Eq. 35 bounce velocity matched within %.3g %%\n",
                  100 * r["calibration"]["worst_bounce_velocity_error"].get<double>());
    std::printf("results      %s/results.json  %s/restitution.csv  %s/history.csv\n",
                out_dir.c_str(), out_dir.c_str(), out_dir.c_str());
    for (const auto& f : r["files"])
      if (f.get<std::string>().ends_with(".svg"))
        std::printf("plot         %s/%s\n", out_dir.c_str(), f.get<std::string>().c_str());
  }
};

} // namespace

std::unique_ptr<LabProtocol> make_drop_test() {
  return std::make_unique<DropTest>();
}

} // namespace rocklab
