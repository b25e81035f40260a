#include "lab/fractures.hpp"

#include "io/results.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <ostream>
#include <unordered_map>

namespace rocklab {

EventClustering monitored_events(const std::vector<Crack>& cracks, const AeMonitor& monitor,
                                 int dim) {
  EventClustering ev;
  ev.event_of_crack = monitor.event_of_crack();
  ev.sources = monitor.sources();
  ev.dim = dim;
  ev.events = events_until(cracks, ev, INFINITY);
  return ev;
}

std::vector<FractureEvent> events_until(const std::vector<Crack>& cracks, const EventClustering& ev,
                                        double until) {
  std::vector<FractureEvent> out;
  int ids = 0;
  for (const int id : ev.event_of_crack)
    ids = std::max(ids, id + 1);
  std::vector<int> index(static_cast<std::size_t>(ids), -1); // event id -> position in out
  std::vector<std::vector<std::uint64_t>> contacts(static_cast<std::size_t>(ids));
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
    if (static_cast<std::size_t>(e.id) < ev.sources.size() &&
        ev.sources[static_cast<std::size_t>(e.id)].m0 > 0) {
      e.has_source = true;
      e.tensor = ev.sources[static_cast<std::size_t>(e.id)].tensor;
      e.source = read_source(e.tensor, ev.dim);
    }
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
         "magnitude,m0_Nm,moment_magnitude,source_type,r_feignier_young,isotropic,double_couple,"
         "clvd,t_axis_x,t_axis_y,t_axis_z,p_axis_x,p_axis_y,p_axis_z,m_xx_Nm,m_yy_Nm,m_zz_Nm,"
         "m_xy_Nm,m_yz_Nm,m_zx_Nm\n";
  auto num = [](double v) { return std::isfinite(v) ? format_double(v) : std::string(); };
  std::string s; // one row at a time
  for (const FractureEvent& e : events) {
    s = std::to_string(e.id) + ',' + format_double(e.time) + ',' + format_double(e.duration);
    for (int k = 0; k < 3; ++k)
      s += ',' + format_double(e.position[k]);
    s += ',' + std::to_string(e.cracks) + ',' + std::to_string(e.contacts) + ',' +
         std::to_string(e.tension) + ',' + std::to_string(e.shear) + ',' + format_double(e.energy) +
         ',' + num(e.magnitude);
    if (e.has_source) {
      const SourceReading& r = e.source;
      s += ',' + num(r.m0) + ',' + num(r.mw) + ',' + to_string(r.type) + ',' + num(r.r) + ',' +
           num(r.isotropic) + ',' + num(r.double_couple) + ',' + num(r.clvd);
      for (const Vec3& a : {r.t_axis, r.p_axis})
        for (int k = 0; k < 3; ++k)
          s += ',' + num(a[k]);
      const Mat3& m = e.tensor;
      for (const double v : {m(0, 0), m(1, 1), m(2, 2), m(0, 1), m(1, 2), m(2, 0)})
        s += ',' + num(v);
    } else {
      s += std::string(19, ',');
    }
    s += '\n';
    out << s;
  }
}

} // namespace rocklab
