#include "io/results.hpp"

#include "contact/model_json.hpp"

#include <charconv>
#include <cmath>
#include <ostream>

namespace rocklab {

namespace {
nlohmann::json vec_json(const Vec3& v, int dim) {
  if (dim == 2)
    return nlohmann::json::array({v.x(), v.y()});
  return nlohmann::json::array({v.x(), v.y(), v.z()});
}

} // namespace

std::string format_double(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

nlohmann::json energy_json(const EnergyLedger& e) {
  return {{"kinetic", e.kinetic()},
          {"kinetic_translational", e.kinetic_translational},
          {"kinetic_rotational", e.kinetic_rotational},
          {"strain", e.strain},
          {"bond_strain", e.bond_strain},
          {"body_work", e.body_work},
          {"gravity_work", e.gravity_work},
          {"boundary_work", e.boundary_work},
          {"local_damping", e.local_damping},
          {"slip", e.slip},
          {"dashpot", e.dashpot},
          {"plastic", e.plastic},
          {"bond_break", e.bond_break},
          {"initial_total", e.initial_total},
          {"balance_error", e.balance_error()}};
}

namespace {

nlohmann::json ball_json(const Model& m, std::size_t i) {
  const int dim = m.settings.dim;
  const Balls& b = m.balls;
  nlohmann::json jb{{"id", b.id[i]},
                    {"group", m.group_names[static_cast<std::size_t>(b.group[i])]},
                    {"radius", b.radius[i]},
                    {"mass", b.mass[i]},
                    {"position", vec_json(b.pos[i], dim)},
                    {"velocity", vec_json(b.vel[i], dim)},
                    {"force", vec_json(b.force[i], dim)}};
  if (dim == 2) {
    jb["spin"] = b.spin[i].z();
    jb["moment"] = b.moment[i].z();
  } else {
    jb["spin"] = vec_json(b.spin[i], dim);
    jb["moment"] = vec_json(b.moment[i], dim);
  }
  if (b.tracks_orientation()) {
    const Eigen::Quaterniond& q = b.orient[i];
    if (dim == 2) // the angle turned about z, in [-pi, pi]
      jb["orientation"] = rotation_vector(q).z();
    else
      jb["orientation"] = {q.w(), q.x(), q.y(), q.z()};
  }
  return jb;
}

nlohmann::json contact_json(const Model& m, std::size_t ci) {
  const int dim = m.settings.dim;
  const Balls& b = m.balls;
  const Contact& c = m.contacts()[ci];
  const ContactOutput& o = m.contact_outputs()[ci];
  const ContactResult local = local_components(c, o);
  const bool bb = c.kind == ContactKind::BallBall;
  nlohmann::json jc{{"kind", bb ? "ball-ball" : "ball-facet"},
                    {"model", std::string(model_name(c.model))},
                    {"end1", b.id[static_cast<std::size_t>(c.end1)]},
                    {"end2", bb ? nlohmann::json(b.id[static_cast<std::size_t>(c.end2)])
                                : nlohmann::json(m.walls[static_cast<std::size_t>(c.end2)].name)},
                    {"position", vec_json(o.xc, dim)},
                    {"normal", vec_json(c.n, dim)},
                    {"gap", c.gap},
                    {"force", vec_json(o.force, dim)},
                    {"moment", dim == 2 ? nlohmann::json(o.moment.z()) : vec_json(o.moment, dim)},
                    {"force_local", {{"Fn", local.Fn}, {"Fss", local.Fss}, {"Fst", local.Fst}}},
                    {"moment_local", {{"Mt", local.Mt}, {"Mbs", local.Mbs}, {"Mbt", local.Mbt}}}};
  jc["state"] = contact_state_json(m.batches(), c.model, c.slot, dim);
  return jc;
}

/// Everything of results.json but the ball and contact lists.
nlohmann::json results_head(const Model& m, const EventCounts& counts,
                            const std::string& scene_file) {
  const int dim = m.settings.dim;
  nlohmann::json out;
  out["rocklab_version"] = ROCKLAB_VERSION;
  out["units"] = "SI: m, kg, s, N, N m, Pa, J, rad";
  out["scene"] = scene_file;
  out["dimension"] = dim;
  out["step"] = m.step();
  out["time_s"] = m.time();
  out["timestep_s"] = m.timestep();
  out["energy_J"] = energy_json(m.energy());
  out["events"] = {{"contact_created", counts.created},
                   {"contact_deleted", counts.deleted},
                   {"slip_change", counts.slip_change},
                   {"bond_break", counts.bond_break}};
  nlohmann::json walls = nlohmann::json::array();
  for (const Wall& w : m.walls) {
    nlohmann::json jw{
        {"name", w.name}, {"center", vec_json(w.center, dim)}, {"force", vec_json(w.force, dim)}};
    if (dim == 2)
      jw["moment"] = w.moment.z();
    else
      jw["moment"] = vec_json(w.moment, dim);
    walls.push_back(std::move(jw));
  }
  out["walls"] = std::move(walls);
  return out;
}

// v.dump(1) written at nesting depth `depth` (its inner lines shifted right by depth spaces), as
// nlohmann::json's own dump(1) of the enclosing document would write it.
void write_nested(std::ostream& os, const nlohmann::json& v, int depth) {
  const std::string text = v.dump(1);
  const std::string pad(static_cast<std::size_t>(depth), ' ');
  std::size_t from = 0;
  for (std::size_t nl; (nl = text.find('\n', from)) != std::string::npos; from = nl + 1)
    os.write(text.data() + from, static_cast<std::streamsize>(nl + 1 - from)) << pad;
  os.write(text.data() + from, static_cast<std::streamsize>(text.size() - from));
}

// A list of n items, made and written one at a time: the file never exists as one document in
// memory (a 10k-sphere flat-jointed model's contact list is ~250 MB of text, ~1.5 GB as a DOM).
template <class Item> void write_list(std::ostream& os, std::size_t n, Item item) {
  if (n == 0) {
    os << "[]";
    return;
  }
  os << "[\n";
  for (std::size_t i = 0; i < n; ++i) {
    os << "  ";
    write_nested(os, item(i), 2);
    os << (i + 1 < n ? ",\n" : "\n");
  }
  os << " ]";
}

} // namespace

nlohmann::json results_json(const Model& m, const EventCounts& counts,
                            const std::string& scene_file) {
  nlohmann::json out = results_head(m, counts, scene_file);
  nlohmann::json balls = nlohmann::json::array();
  for (std::size_t i = 0; i < m.balls.size(); ++i)
    balls.push_back(ball_json(m, i));
  out["balls"] = std::move(balls);
  nlohmann::json contacts = nlohmann::json::array();
  for (std::size_t ci = 0; ci < m.contacts().size(); ++ci)
    contacts.push_back(contact_json(m, ci));
  out["contacts"] = std::move(contacts);
  return out;
}

bool contacts_written(ContactOutputMode mode, std::size_t contacts) {
  return mode == ContactOutputMode::Always ||
         (mode == ContactOutputMode::Auto && contacts <= kContactsAutoLimit);
}

void write_results_json(std::ostream& os, const Model& m, const EventCounts& counts,
                        const std::string& scene_file, ContactOutputMode mode) {
  nlohmann::json head = results_head(m, counts, scene_file);
  const std::size_t nc = m.contacts().size();
  const bool with_contacts = contacts_written(mode, nc);
  head["balls"] = nullptr;
  head["contact_count"] = nc;
  if (with_contacts)
    head["contacts"] = nullptr;
  else
    head["contacts_omitted"] =
        mode == ContactOutputMode::Never
            ? "per-contact state not written (scene output.contacts is false)"
            : "per-contact state not written: " + std::to_string(nc) + " contacts > " +
                  std::to_string(kContactsAutoLimit) +
                  " (set the scene's output.contacts to true to write it)";
  // Keys in the document's own (sorted) order, the two lists streamed in place of their nulls.
  os << "{\n";
  std::size_t k = 0;
  for (auto it = head.begin(); it != head.end(); ++it, ++k) {
    os << " " << nlohmann::json(it.key()).dump() << ": ";
    if (it.key() == "balls")
      write_list(os, m.balls.size(), [&](std::size_t i) { return ball_json(m, i); });
    else if (it.key() == "contacts")
      write_list(os, nc, [&](std::size_t i) { return contact_json(m, i); });
    else
      write_nested(os, it.value(), 1);
    os << (k + 1 < head.size() ? ",\n" : "\n");
  }
  os << "}\n";
}

std::string history_header(const std::vector<HistoryColumn>& cols) {
  std::string s;
  for (std::size_t k = 0; k < cols.size(); ++k) {
    if (k)
      s += ',';
    s += cols[k].name;
  }
  s += '\n';
  return s;
}

std::string history_row(const Model& m, const std::vector<HistoryColumn>& cols,
                        const EventCounts& counts) {
  const EnergyLedger e = m.energy();
  std::vector<EnergyLedger> groups;
  for (const HistoryColumn& c : cols)
    if (c.kind == HistoryColumn::Kind::GroupEnergy) {
      groups = m.group_energy();
      break;
    }
  std::string s;
  for (std::size_t k = 0; k < cols.size(); ++k) {
    if (k)
      s += ',';
    s += format_double(history_value(m, cols[k], e, counts, groups));
  }
  s += '\n';
  return s;
}

} // namespace rocklab
