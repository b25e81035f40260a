// One crack per contact and fracture events from crack records (lab/fractures): merging of a
// flat joint's element cracks, the events' sums, their state as of a time, events.csv. How cracks
// join events is lab/ae_monitor's (tests/test_acoustic_emission.cpp).
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

// The events of `cs` when crack i belongs to event of[i].
EventClustering clustered(const std::vector<Crack>& cs, const std::vector<int>& of) {
  EventClustering ev;
  ev.event_of_crack = of;
  ev.events = events_until(cs, ev, INFINITY);
  return ev;
}

TEST(Fractures, AFlatJointsElementCracksAreOneContactCrack) {
  // 3 of 8 elements of contact 7 (grains 1-2) break; one whole bond (grains 3-4) breaks.
  const std::vector<Crack> cs = {crack(1.0, 1, 2, 7, 1, 8, 2e-3), crack(1.0, 1, 2, 7, 2, 8, 2e-3),
                                 crack(5.0, 3, 4, 9), crack(9.0, 1, 2, 7, 5, 8, 2e-3, 1e-4, 2)};
  const EventClustering ev = clustered(cs, {0, 0, 1, 2});
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

TEST(Fractures, AnEventSumsItsCracksAndIsReadAsOfATime) {
  const std::vector<Crack> cs = {crack(0.0, 1, 2, 100),   crack(0.4, 3, 4, 101),
                                 crack(0.5, 10, 11, 102), crack(2.0, 1, 2, 103),
                                 crack(2.9, 3, 4, 104),   crack(3.3, 3, 4, 105, -1, 1, 1e-3, 4e-4)};
  const EventClustering ev = clustered(cs, {0, 0, 1, 2, 3, 3});
  ASSERT_EQ(ev.events.size(), 4u);
  EXPECT_EQ(ev.events[0].cracks, 2);
  EXPECT_EQ(ev.events[0].contacts, 2);
  EXPECT_DOUBLE_EQ(ev.events[0].duration, 0.4);
  EXPECT_DOUBLE_EQ(ev.events[3].energy, 5e-4);
  EXPECT_NEAR(ev.events[3].magnitude, (std::log10(5e-4) - 4.8) / 1.5, 1e-12);
  // the centroid of event 0: cracks at x = 3 mm and 7 mm
  EXPECT_NEAR(ev.events[0].position.x(), 5e-3, 1e-15);
  EXPECT_FALSE(ev.events[0].has_source); // no moment tensors given
  // As of t = 2.0: the first four cracks' events, with what they had then.
  const auto part = events_until(cs, ev, 2.0);
  ASSERT_EQ(part.size(), 3u);
  EXPECT_EQ(part[2].id, 2);
  EXPECT_EQ(part[0].cracks, 2);
}

TEST(Fractures, EventsCsvHasAHeaderAndARowPerEventWithTheirSources) {
  const std::vector<Crack> cs = {crack(0.0, 1, 2, 100), crack(1.0, 5, 6, 101)};
  EventClustering ev;
  ev.event_of_crack = {0, 1};
  AeSource tensile;
  tensile.tensor = Mat3::Zero();
  tensile.tensor(0, 0) = 2e3; // N m
  tensile.m0 = 2e3 / std::sqrt(2.0);
  ev.sources = {tensile, AeSource{}};
  ev.events = events_until(cs, ev, INFINITY);
  ASSERT_TRUE(ev.events[0].has_source);
  EXPECT_FALSE(ev.events[1].has_source); // M0 = 0: no source
  std::ostringstream written;
  write_events_csv(written, ev.events);
  const std::string csv = written.str();
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3);
  EXPECT_EQ(csv.rfind("event,time_s,", 0), 0u);
  std::istringstream lines(csv);
  std::string header, row0, row1;
  std::getline(lines, header), std::getline(lines, row0), std::getline(lines, row1);
  const auto commas = [](const std::string& x) { return std::count(x.begin(), x.end(), ','); };
  EXPECT_EQ(commas(row0), commas(header));
  EXPECT_EQ(commas(row1), commas(header));
  EXPECT_NE(row0.find(",tensile,"), std::string::npos);
}

} // namespace
} // namespace rocklab
