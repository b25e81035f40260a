// Scene history columns: parsed from their names (docs/scene-format.md) and evaluated on the model.
#include "io/scene_parts.hpp"

#include "io/results.hpp"

#include <algorithm>
#include <map>

namespace rocklab {

namespace scene_detail {

namespace {

// One history column, parsed from its name (docs/scene-format.md); errors name the column.
class ColumnParser {
public:
  ColumnParser(const Model& m, std::string file, std::string path, std::string name)
      : m_(m), file_(std::move(file)), path_(std::move(path)), name_(std::move(name)) {
    std::size_t start = 0;
    for (;;) {
      const std::size_t slash = name_.find('/', start);
      parts_.push_back(name_.substr(start, slash - start));
      if (slash == std::string::npos)
        break;
      start = slash + 1;
    }
    // The partitions a column may name: those of results.json's energy record.
    energies_ = energy_json(EnergyLedger{});
  }

  HistoryColumn parse() {
    HistoryColumn c;
    c.name = name_;
    static const std::map<std::string, HistoryColumn::Kind> simple{
        {"step", HistoryColumn::Kind::Step},
        {"time", HistoryColumn::Kind::Time},
        {"timestep", HistoryColumn::Kind::Timestep},
        {"contacts", HistoryColumn::Kind::Contacts},
        {"active_contacts", HistoryColumn::Kind::ActiveContacts},
        {"unbalanced_force_ratio", HistoryColumn::Kind::Ratio}};
    const std::string& head = parts_[0];
    const std::size_t n = parts_.size();
    if (auto it = simple.find(name_); it != simple.end())
      c.kind = it->second;
    else if (head == "events" && n == 2)
      events(c);
    else if (head == "energy" && n == 2)
      energy(c);
    else if (head == "ball" && n == 4)
      ball(c);
    else if (head == "wall" && n == 4)
      wall(c);
    else if (head == "group" && n == 3)
      group(c);
    else if (head == "clump" && n == 4)
      clump(c);
    else
      bad("is not known (see docs/scene-format.md: step, time, timestep, contacts, "
          "active_contacts, unbalanced_force_ratio, energy/NAME, events/NAME, "
          "ball/ID/QUANTITY/COMPONENT, wall/NAME/QUANTITY/COMPONENT, group/NAME/PARTITION, "
          "clump/ID/QUANTITY/COMPONENT)");
    return c;
  }

private:
  [[noreturn]] void bad(const std::string& why) const {
    throw InputError(file_ + ": key '" + path_ + "': column \"" + name_ + "\" " + why);
  }
  bool is_energy(const std::string& q) const {
    return energies_.contains(q) && q != "initial_total";
  }
  std::int64_t parse_id(const std::string& what) const {
    std::size_t used = 0;
    std::int64_t id = 0;
    try {
      id = std::stoll(parts_[1], &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != parts_[1].size())
      bad("has a " + what + " id that is not an integer");
    return id;
  }
  int component(const std::string& comp) const {
    static const std::map<std::string, int> comps{{"x", 0}, {"y", 1}, {"z", 2}, {"mag", 3}};
    auto it = comps.find(comp);
    if (it == comps.end())
      bad("has component \"" + comp + "\" (allowed: x, y, z, mag)");
    return it->second;
  }
  void events(HistoryColumn& c) const {
    c.kind = HistoryColumn::Kind::Events;
    c.quantity = parts_[1];
    if (c.quantity != "contact_created" && c.quantity != "contact_deleted" &&
        c.quantity != "slip_change" && c.quantity != "bond_break")
      bad("names an unknown event (allowed: contact_created, contact_deleted, slip_change, "
          "bond_break)");
  }
  void energy(HistoryColumn& c) const {
    c.kind = HistoryColumn::Kind::Energy;
    c.quantity = parts_[1];
    if (!is_energy(c.quantity))
      bad("names an unknown energy partition");
  }
  void ball(HistoryColumn& c) const {
    c.kind = HistoryColumn::Kind::Ball;
    const std::int64_t id = parse_id("ball");
    auto it = std::find(m_.balls.id.begin(), m_.balls.id.end(), id);
    if (it == m_.balls.id.end())
      bad("names ball id " + parts_[1] + ", which does not exist");
    c.index = static_cast<std::size_t>(it - m_.balls.id.begin());
    c.quantity = parts_[2];
    if (c.quantity != "position" && c.quantity != "velocity" && c.quantity != "spin" &&
        c.quantity != "force" && c.quantity != "moment")
      bad("has quantity \"" + c.quantity + "\" (allowed: position, velocity, spin, force, moment)");
    c.component = component(parts_[3]);
  }
  void wall(HistoryColumn& c) const {
    c.kind = HistoryColumn::Kind::Wall;
    bool found = false;
    for (std::size_t w = 0; w < m_.walls.size(); ++w)
      if (m_.walls[w].name == parts_[1]) {
        c.index = w;
        found = true;
      }
    if (!found)
      bad("names wall \"" + parts_[1] + "\", which does not exist");
    c.quantity = parts_[2];
    if (c.quantity != "force" && c.quantity != "moment" && c.quantity != "center")
      bad("has quantity \"" + c.quantity + "\" (allowed: force, moment, center)");
    c.component = component(parts_[3]);
  }
  void group(HistoryColumn& c) const {
    c.kind = HistoryColumn::Kind::GroupEnergy;
    auto it = std::find(m_.group_names.begin(), m_.group_names.end(), parts_[1]);
    if (it == m_.group_names.end())
      bad("names group \"" + parts_[1] + "\", which no ball or clump has");
    c.index = static_cast<std::size_t>(it - m_.group_names.begin());
    c.quantity = parts_[2];
    if (!is_energy(c.quantity) || c.quantity == "boundary_work" || c.quantity == "balance_error")
      bad("names an energy partition that is not traced per group (allowed: kinetic, "
          "kinetic_translational, kinetic_rotational, strain, bond_strain, body_work, "
          "gravity_work, local_damping, slip, dashpot, plastic, bond_break)");
  }
  void clump(HistoryColumn& c) const {
    c.kind = HistoryColumn::Kind::Clump;
    const std::int64_t id = parse_id("clump");
    auto it = std::find_if(m_.clumps.begin(), m_.clumps.end(),
                           [&](const Clump& k) { return k.id == id; });
    if (it == m_.clumps.end())
      bad("names clump id " + parts_[1] + ", which does not exist");
    c.index = static_cast<std::size_t>(it - m_.clumps.begin());
    c.quantity = parts_[2];
    if (c.quantity != "position" && c.quantity != "velocity" && c.quantity != "spin" &&
        c.quantity != "angular_momentum")
      bad("has quantity \"" + c.quantity +
          "\" (allowed: position, velocity, spin, angular_momentum)");
    c.component = component(parts_[3]);
  }

  const Model& m_;
  std::string file_, path_, name_;
  std::vector<std::string> parts_;
  nlohmann::json energies_;
};

} // namespace

void read_history(JsonObject& top, Scene& s) {
  if (!top.has("history"))
    return;
  JsonObject h = top.object("history");
  s.history_every = h.integer("every", 1, std::numeric_limits<std::int32_t>::max(), 100);
  for (const auto& [jc, path] : h.array("columns")) {
    if (!jc->is_string())
      throw InputError(top.file() + ": key '" + path + "': expected a column name, got " +
                       describe(*jc));
    s.history.push_back(ColumnParser(*s.model, top.file(), path, jc->get<std::string>()).parse());
  }
  h.finish();
}

} // namespace scene_detail

void EventCounts::add(const std::vector<Event>& events) {
  for (const Event& e : events) {
    switch (e.type) {
    case EventType::ContactCreated:
      ++created;
      break;
    case EventType::ContactDeleted:
      ++deleted;
      break;
    case EventType::SlipChange:
      ++slip_change;
      break;
    case EventType::BondBreak:
      ++bond_break;
      break;
    }
  }
}

double energy_partition(const EnergyLedger& e, const std::string& name) {
  return energy_json(e).at(name).get<double>();
}

double history_value(const Model& m, const HistoryColumn& c, const EnergyLedger& e,
                     const EventCounts& counts, const std::vector<EnergyLedger>& groups) {
  auto comp = [&](const Vec3& v) { return c.component == 3 ? v.norm() : v[c.component]; };
  switch (c.kind) {
  case HistoryColumn::Kind::Step:
    return static_cast<double>(m.step());
  case HistoryColumn::Kind::Time:
    return m.time();
  case HistoryColumn::Kind::Timestep:
    return m.timestep();
  case HistoryColumn::Kind::Contacts:
    return static_cast<double>(m.contacts().size());
  case HistoryColumn::Kind::ActiveContacts:
    return static_cast<double>(m.active_contact_count());
  case HistoryColumn::Kind::Ratio:
    return m.mean_unbalanced_force_ratio(true);
  case HistoryColumn::Kind::Events:
    if (c.quantity == "contact_created")
      return static_cast<double>(counts.created);
    if (c.quantity == "contact_deleted")
      return static_cast<double>(counts.deleted);
    if (c.quantity == "slip_change")
      return static_cast<double>(counts.slip_change);
    return static_cast<double>(counts.bond_break);
  case HistoryColumn::Kind::Energy:
    return energy_partition(e, c.quantity);
  case HistoryColumn::Kind::GroupEnergy:
    return c.index < groups.size() ? energy_partition(groups[c.index], c.quantity) : 0.0;
  case HistoryColumn::Kind::Clump: {
    const Clump& k = m.clumps[c.index];
    if (c.quantity == "position")
      return comp(k.pos);
    if (c.quantity == "velocity")
      return comp(k.vel);
    if (c.quantity == "spin")
      return comp(k.spin);
    return comp(k.L);
  }
  case HistoryColumn::Kind::Ball: {
    const std::size_t i = c.index;
    const Balls& b = m.balls;
    if (c.quantity == "position")
      return comp(b.pos[i]);
    if (c.quantity == "velocity")
      return comp(b.vel[i]);
    if (c.quantity == "spin")
      return comp(b.spin[i]);
    if (c.quantity == "force")
      return comp(b.force[i]);
    return comp(b.moment[i]);
  }
  case HistoryColumn::Kind::Wall: {
    const Wall& w = m.walls[c.index];
    if (c.quantity == "force")
      return comp(w.force);
    if (c.quantity == "moment")
      return comp(w.moment);
    return comp(w.center);
  }
  }
  return 0;
}

} // namespace rocklab
