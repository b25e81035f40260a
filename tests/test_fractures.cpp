// One crack per contact and fracture events from crack records (lab/fractures): merging of a
// flat joint's element cracks, clustering by touching grains and time window, causality.
#include "helpers.hpp"
#include "lab/fractures.hpp"

#include <cmath>
#include <sstream>

namespace rocklab {
namespace {

Crack crack(double t, std::int64_t b1, std::int64_t b2, std::uint64_t contact, int element = -1,
            int parts = 1, double size = 1e-3, double energy = 1e-4, int mode = 1) {
  Crack c;
  c.time = t;
  c.ball1 = b1, c.ball2 = b2;
  c.contact = contact;
  c.element = element;
  c.parts = parts;
  c.size = size;
  c.energy = energy;
  c.mode = mode;
  c.position = Vec3(static_cast<double>(b1 + b2), 0, 0) * 1e-3;
  c.normal = Vec3::UnitX();
  return c;
}

TEST(Fractures, AFlatJointsElementCracksAreOneContactCrack) {
  // 3 of 8 elements of contact 7 (grains 1-2) break; one whole bond (grains 3-4) breaks.
  const std::vector<Crack> cs = {crack(1.0, 1, 2, 7, 1, 8, 2e-3), crack(1.0, 1, 2, 7, 2, 8, 2e-3),
                                 crack(5.0, 3, 4, 9), crack(9.0, 1, 2, 7, 5, 8, 2e-3, 1e-4, 2)};
  const EventClustering ev = cluster_events(cs, {}, 0.5);
  const auto all = contact_cracks(cs, ev, INFINITY, 3);
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all[0].contact, 7u);
  EXPECT_EQ(all[0].broken, 3);
  EXPECT_EQ(all[0].parts, 8);
  EXPECT_DOUBLE_EQ(all[0].damage(), 3.0 / 8.0);
  EXPECT_NEAR(all[0].size, std::sqrt(3.0) * 2e-3, 1e-15); // the summed area's diameter
  EXPECT_EQ(all[0].mode(), 1);                            // 2 tension, 1 shear
  EXPECT_DOUBLE_EQ(all[0].time, 1.0);
  EXPECT_DOUBLE_EQ(all[1].damage(), 1.0);
  // 2D: lengths add
  EXPECT_NEAR(contact_cracks(cs, ev, INFINITY, 2)[0].size, 6e-3, 1e-15);
  // as of t = 5: the first contact has two elements broken
  const auto early = contact_cracks(cs, ev, 5.0, 3);
  ASSERT_EQ(early.size(), 2u);
  EXPECT_EQ(early[0].broken, 2);
}

TEST(Fractures, CracksAtTouchingGrainsWithinTheWindowAreOneEvent) {
  // grains 1-2-3-4 in a chain (1 touches 2, ...); 10 and 11 touch nothing of them
  const TouchingPairs touching = {{1, 2}, {2, 3}, {3, 4}, {10, 11}};
  const std::vector<Crack> cs = {
      crack(0.0, 1, 2, 100),   // event 0
      crack(0.4, 3, 4, 101),   // grain 3 touches grain 2 of crack 0, 0.4 <= window: event 0
      crack(0.5, 10, 11, 102), // touches nothing: event 1
      crack(2.0, 1, 2, 103),   // same grains but 1.6 after the last crack there: event 2
      crack(2.9, 3, 4, 104),   // 0.9 after crack 3 at a touching grain: beyond 0.5, event 3
      crack(3.3, 3, 4, 105, -1, 1, 1e-3, 4e-4)}; // 0.4 after crack 4: event 3
  const EventClustering ev = cluster_events(cs, touching, 0.5);
  EXPECT_EQ(ev.event_of_crack, (std::vector<int>{0, 0, 1, 2, 3, 3}));
  ASSERT_EQ(ev.events.size(), 4u);
  EXPECT_EQ(ev.events[0].cracks, 2);
  EXPECT_EQ(ev.events[0].contacts, 2);
  EXPECT_DOUBLE_EQ(ev.events[0].duration, 0.4);
  EXPECT_DOUBLE_EQ(ev.events[3].energy, 5e-4);
  EXPECT_NEAR(ev.events[3].magnitude, (std::log10(5e-4) - 4.8) / 1.5, 1e-12);
  // the centroid of event 0: cracks at x = 3 mm and 7 mm
  EXPECT_NEAR(ev.events[0].position.x(), 5e-3, 1e-15);
  // Causal: the events as of t = 2.0 are those of the first four cracks clustered alone.
  const std::vector<Crack> prefix(cs.begin(), cs.begin() + 4);
  const auto part = events_until(cs, ev, 2.0);
  const auto alone = cluster_events(prefix, touching, 0.5).events;
  ASSERT_EQ(part.size(), alone.size());
  for (std::size_t i = 0; i < part.size(); ++i) {
    EXPECT_EQ(part[i].id, alone[i].id);
    EXPECT_EQ(part[i].cracks, alone[i].cracks);
  }
}

TEST(Fractures, TheDefaultWindowIsAPWaveCrossingFiveGrains) {
  // E 50 GPa, 2650 kg/m3: c = 4343.6 m/s; 5 x 1.6 mm / c
  EXPECT_NEAR(default_event_window(5e10, 2650, 1.6e-3), 8e-3 / std::sqrt(5e10 / 2650), 1e-18);
  EXPECT_EQ(default_event_window(0, 2650, 1e-3), 0);
  // events.csv: a header and a row per event
  const std::vector<Crack> cs = {crack(0.0, 1, 2, 100), crack(1.0, 5, 6, 101)};
  std::ostringstream written;
  write_events_csv(written, cluster_events(cs, {}, 0.1).events);
  const std::string csv = written.str();
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3);
  EXPECT_EQ(csv.rfind("event,time_s,", 0), 0u);
}

} // namespace
} // namespace rocklab
