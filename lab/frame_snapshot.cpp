#include "lab/frame_snapshot.hpp"

#include "io/results.hpp"
#include "lab/ae_report.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace rocklab {

ClipShape specimen_outline(const LoadingFrame& f) {
  const SpecimenGeometry& g = f.geometry();
  const Balls& b = f.model().balls;
  ClipShape c;
  c.dim = g.dim;
  c.round = g.round || g.diametral;
  c.lo = g.lo, c.hi = g.hi;
  c.center = Vec3(g.center.x(), g.center.y(), 0);
  if (g.diametral) {
    c.radius = 0.25 * (g.width0.x() + g.width0.y());
    c.fit_round_box();
    return c;
  }
  const int a = g.axis;
  double lo = 1e300, hi = -1e300;
  for (std::size_t i = 0; i < b.size(); ++i)
    lo = std::min(lo, b.pos[i][a] - b.radius[i]), hi = std::max(hi, b.pos[i][a] + b.radius[i]);
  const double area = f.current_area(f.current().lateral_strain), h = f.current_volume() / area;
  c.lo[a] = 0.5 * (lo + hi) - 0.5 * h, c.hi[a] = 0.5 * (lo + hi) + 0.5 * h;
  if (c.round) {
    c.radius = std::sqrt(area / std::numbers::pi);
    c.fit_round_box();
  } else {
    const double scale = std::pow(area / g.area0, g.dim == 2 ? 1.0 : 0.5);
    for (int d = 0; d < g.dim; ++d)
      if (d != a) {
        const double mid = 0.5 * (g.lo[d] + g.hi[d]), half = 0.5 * g.width0[d] * scale;
        c.lo[d] = mid - half, c.hi[d] = mid + half;
      }
  }
  return c;
}

Snapshot frame_snapshot(const LoadingFrame& f) {
  Snapshot s = take_snapshot(f.model(), f.reference_positions(), f.current().axial_strain,
                             f.current().axial_stress, f.current_volume());
  s.outline = specimen_outline(f);
  for (const Crack& c : f.cracks().cracks())
    s.cracks.push_back({c.position, c.normal, c.size, c.mode, c.time, c.step});
  return s;
}

void add_fractures(Snapshot& s, const std::vector<Crack>& cracks, const EventClustering& ev,
                   double until) {
  for (const ContactCrack& c : contact_cracks(cracks, ev, until, s.dim)) {
    s.contact_cracks.push_back(
        {c.position, c.normal, c.size, c.mode(), c.time, 0, c.damage(), c.event, c.energy});
    s.contact_crack_grains.push_back({c.ball1, c.ball2});
  }
  for (const FractureEvent& e : events_until(cracks, ev, until)) {
    EventGlyph g{e.id, e.position, e.time, e.duration, e.cracks, e.contacts, e.energy, e.magnitude};
    if (e.has_source) {
      g.moment_magnitude = e.source.mw;
      g.source_type = static_cast<int>(e.source.type);
      g.r = e.source.r;
    }
    s.events.push_back(g);
  }
}

EventClustering fracture_events(const LoadingFrame& f, const Protocol& p, nlohmann::json& r) {
  const AeMonitor& ae = f.acoustic_emission();
  const int dim = f.model().settings.dim;
  EventClustering ev = monitored_events(f.cracks().cracks(), ae, dim);
  std::size_t largest = 0;
  for (const FractureEvent& x : ev.events)
    largest = std::max(largest, static_cast<std::size_t>(x.cracks));
  const std::string duration =
      p.event_window > 0
          ? "output.event_window_s: each crack keeps its event open " +
                format_double(p.event_window) + " s"
          : "each crack keeps its event open while a rupture at half the shear-wave speed "
            "crosses the crack's larger grain (Hazzard & Young 2000); the speed sqrt(G / rho), G "
            "the affine shear modulus of the grain contacts and rho the grains' mass over the "
            "specimen's volume at the first crack";
  r["fracture_events"] = {
      {"count", ev.events.size()},
      {"broken_contacts", contact_cracks(f.cracks().cracks(), ev, INFINITY, dim).size()},
      {"largest_event_cracks", largest},
      {"shear_wave_speed_m_per_s", ae.shear_wave_speed()},
      {"duration_rule", duration},
      {"method", "a crack joins the open event whose source grains (the grains of its cracks) it "
                 "shares or touches, else opens one (Hazzard & Young 2000, 2004); magnitude: "
                 "log10 E = 1.5 M + 4.8 of the released bond strain energy E [J]"}};
  if (p.moment_tensors)
    r["acoustic_emission"] =
        acoustic_emission_summary(ev.events, json_number(r, "peak_time_s", NAN));
  return ev;
}

} // namespace rocklab
