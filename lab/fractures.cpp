#include "lab/fractures.hpp"

#include "io/results.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <ostream>
#include <unordered_map>

namespace rocklab {

TouchingPairs touching_pairs(const Model& m) {
  TouchingPairs t;
  for (const Contact& c : m.contacts())
    if (c.kind == ContactKind::BallBall)
      t.emplace_back(m.balls.id[static_cast<std::size_t>(c.end1)],
                     m.balls.id[static_cast<std::size_t>(c.end2)]);
  return t;
}

double default_event_window(double youngs_modulus, double bulk_density, double mean_diameter,
                            double diameters) {
  if (!(youngs_modulus > 0) || !(bulk_density > 0) || !(mean_diameter > 0))
    return 0;
  return diameters * mean_diameter / std::sqrt(youngs_modulus / bulk_density);
}

EventClustering cluster_events(const std::vector<Crack>& cracks, const TouchingPairs& touching,
                               double window) {
  EventClustering ev;
  ev.window = window;
  // Grains that touch: the model's contacts and every cracked contact (whose grains may have
  // separated since).
  std::unordered_map<std::int64_t, std::vector<std::int64_t>> nb;
  auto link = [&](std::int64_t a, std::int64_t b) {
    if (a < 0 || b < 0)
      return;
    nb[a].push_back(b);
    nb[b].push_back(a);
  };
  for (const auto& [a, b] : touching)
    link(a, b);
  for (const Crack& c : cracks)
    link(c.ball1, c.ball2);
  // The latest crack at each grain: (event, time).
  std::unordered_map<std::int64_t, std::pair<int, double>> last;
  ev.event_of_crack.reserve(cracks.size());
  for (const Crack& c : cracks) {
    int join = -1;
    auto look = [&](std::int64_t g) {
      const auto it = last.find(g);
      if (it != last.end() && it->second.second >= c.time - window &&
          (join < 0 || it->second.first < join))
        join = it->second.first;
    };
    for (const std::int64_t g : {c.ball1, c.ball2}) {
      if (g < 0)
        continue;
      look(g);
      const auto it = nb.find(g);
      if (it != nb.end())
        for (const std::int64_t h : it->second)
          look(h);
    }
    if (join < 0) {
      join = static_cast<int>(ev.events.size());
      ev.events.push_back({});
      ev.events.back().id = join;
    }
    ev.event_of_crack.push_back(join);
    for (const std::int64_t g : {c.ball1, c.ball2})
      if (g >= 0)
        last[g] = {join, c.time};
  }
  ev.events = events_until(cracks, ev, INFINITY);
  return ev;
}

std::vector<FractureEvent> events_until(const std::vector<Crack>& cracks, const EventClustering& ev,
                                        double until) {
  std::vector<FractureEvent> out;
  std::vector<int> index(ev.events.size(), -1); // event id -> position in out
  std::vector<std::vector<std::uint64_t>> contacts(ev.events.size());
  for (std::size_t i = 0; i < cracks.size() && i < ev.event_of_crack.size(); ++i) {
    const Crack& c = cracks[i];
    if (c.time > until)
      continue;
    const auto id = static_cast<std::size_t>(ev.event_of_crack[i]);
    if (index[id] < 0) {
      index[id] = static_cast<int>(out.size());
      out.push_back({});
      out.back().id = static_cast<int>(id);
      out.back().time = c.time;
    }
    FractureEvent& e = out[static_cast<std::size_t>(index[id])];
    e.duration = c.time - e.time;
    e.position += c.position;
    e.cracks += 1;
    (c.mode == 1 ? e.tension : e.shear) += 1;
    e.energy += c.energy;
    contacts[id].push_back(c.contact);
  }
  for (FractureEvent& e : out) {
    e.position /= e.cracks;
    auto& k = contacts[static_cast<std::size_t>(e.id)];
    std::sort(k.begin(), k.end());
    e.contacts = static_cast<int>(std::unique(k.begin(), k.end()) - k.begin());
    e.magnitude = e.energy > 0 ? (std::log10(e.energy) - 4.8) / 1.5 : NAN;
  }
  return out;
}

std::vector<ContactCrack> contact_cracks(const std::vector<Crack>& cracks,
                                         const EventClustering& ev, double until, int dim) {
  std::vector<ContactCrack> out;
  std::unordered_map<std::uint64_t, std::size_t> at;
  std::vector<double> area;
  for (std::size_t i = 0; i < cracks.size(); ++i) {
    const Crack& c = cracks[i];
    if (c.time > until)
      continue;
    auto [it, fresh] = at.emplace(c.contact, out.size());
    if (fresh) {
      ContactCrack k;
      k.contact = c.contact;
      k.ball1 = c.ball1, k.ball2 = c.ball2;
      k.normal = c.normal;
      k.time = c.time;
      k.parts = c.parts;
      k.event = i < ev.event_of_crack.size() ? ev.event_of_crack[i] : -1;
      k.position = Vec3::Zero();
      out.push_back(k);
      area.push_back(0);
    }
    ContactCrack& k = out[it->second];
    const double w = std::max(dim == 2 ? c.size : c.size * c.size, 1e-300); // area (2D: length)
    k.position += w * c.position;
    area[it->second] += w;
    k.broken += 1;
    k.parts = std::max(k.parts, c.parts);
    (c.mode == 1 ? k.tension : k.shear) += 1;
    k.energy += c.energy;
  }
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i].position /= area[i];
    out[i].size = dim == 2 ? area[i] : std::sqrt(area[i]); // 3D: diameter of the summed area
  }
  return out;
}

void write_events_csv(std::ostream& out, const std::vector<FractureEvent>& events) {
  out << "event,time_s,duration_s,x_m,y_m,z_m,cracks,contacts,tension,shear,energy_J,"
         "magnitude\n";
  std::string s; // one row at a time
  for (const FractureEvent& e : events) {
    s = std::to_string(e.id) + ',' + format_double(e.time) + ',' + format_double(e.duration);
    for (int k = 0; k < 3; ++k)
      s += ',' + format_double(e.position[k]);
    s += ',' + std::to_string(e.cracks) + ',' + std::to_string(e.contacts) + ',' +
         std::to_string(e.tension) + ',' + std::to_string(e.shear) + ',' + format_double(e.energy) +
         ',' + (std::isfinite(e.magnitude) ? format_double(e.magnitude) : "") + '\n';
    out << s;
  }
}

} // namespace rocklab
