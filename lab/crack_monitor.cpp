#include "lab/crack_monitor.hpp"

#include "contact/registry.hpp"
#include "io/results.hpp"

#include <algorithm>

namespace rocklab {

void CrackMonitor::consume(const Model& m, const std::vector<Event>& events) {
  for (const Event& e : events) {
    if (e.type != EventType::BondBreak)
      continue;
    Crack c;
    c.time = e.time;
    c.step = e.step;
    c.position = e.position;
    c.normal = e.normal;
    c.size = e.size;
    c.mode = e.mode;
    c.contact = e.contact;
    c.element = e.element;
    c.gap = e.gap;
    c.strength = e.strength;
    c.energy = e.energy;
    // the bond's parts (flat-joint elements): contacts are sorted by key
    const auto& cs = m.contacts();
    const auto it = std::lower_bound(cs.begin(), cs.end(), e.contact,
                                     [](const Contact& a, std::uint64_t k) { return a.key < k; });
    c.parts = std::max(1, e.element);
    if (it != cs.end() && it->key == e.contact)
      c.parts = std::max(c.parts, contact_bond_view(m.batches(), it->model, it->slot).parts);
    const ContactEnds ends = contact_ends(e.contact);
    c.ball1 = m.balls.id[static_cast<std::size_t>(ends.end1)];
    c.ball2 =
        ends.kind == ContactKind::BallFacet ? -1 : m.balls.id[static_cast<std::size_t>(ends.end2)];
    (c.mode == 1 ? tension_ : shear_) += 1;
    cracks_.push_back(c);
  }
}

void CrackMonitor::write_csv(std::ostream& out) const {
  out << "time_s,step,x_m,y_m,z_m,nx,ny,nz,size_m,mode,ball1,ball2,contact,element,parts,gap_m,"
         "strength_Pa,energy_J\n";
  std::string s; // one row at a time: a 10k-grain test's 24k cracks are 6.7 MB of text
  auto field = [&s](const std::string& v) {
    s += v;
    s += ',';
  };
  for (const Crack& c : cracks_) {
    s.clear();
    field(format_double(c.time));
    field(std::to_string(c.step));
    for (int k = 0; k < 3; ++k)
      field(format_double(c.position[k]));
    for (int k = 0; k < 3; ++k)
      field(format_double(c.normal[k]));
    field(format_double(c.size));
    field(c.mode == 1 ? "tension" : "shear");
    field(std::to_string(c.ball1));
    field(std::to_string(c.ball2));
    field(std::to_string(c.contact));
    field(std::to_string(c.element));
    field(std::to_string(c.parts));
    field(format_double(c.gap));
    field(format_double(c.strength));
    s += format_double(c.energy);
    s += '\n';
    out << s;
  }
}

nlohmann::json CrackMonitor::to_json() const {
  nlohmann::json a = nlohmann::json::array();
  for (const Crack& c : cracks_)
    a.push_back({c.time,
                 c.step,
                 {c.position.x(), c.position.y(), c.position.z()},
                 {c.normal.x(), c.normal.y(), c.normal.z()},
                 c.size,
                 c.mode,
                 c.ball1,
                 c.ball2,
                 c.contact,
                 c.element,
                 c.gap,
                 c.strength,
                 c.energy,
                 c.parts});
  return a;
}

void CrackMonitor::from_json(const nlohmann::json& a) {
  cracks_.clear();
  tension_ = shear_ = 0;
  for (const auto& r : a) {
    Crack c;
    c.time = r[0].get<double>();
    c.step = r[1].get<std::int64_t>();
    for (int k = 0; k < 3; ++k) {
      c.position[k] = r[2][k].get<double>();
      c.normal[k] = r[3][k].get<double>();
    }
    c.size = r[4].get<double>();
    c.mode = r[5].get<int>();
    c.ball1 = r[6].get<std::int64_t>();
    c.ball2 = r[7].get<std::int64_t>();
    c.contact = r[8].get<std::uint64_t>();
    c.element = r[9].get<int>();
    c.gap = r[10].get<double>();
    c.strength = r[11].get<double>();
    c.energy = r[12].get<double>();
    c.parts = r.size() > 13 ? r[13].get<int>() : 1;
    (c.mode == 1 ? tension_ : shear_) += 1;
    cracks_.push_back(c);
  }
}

} // namespace rocklab
