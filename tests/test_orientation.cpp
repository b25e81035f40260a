// Ball orientation tracking (opt-in): a free spin turns a ball by omega t, a clump's pebbles turn
// with the body (their arms are their orientations applied to the starting arms), a rotated model
// gives rotated rotations, tracking changes no trajectory, and orientations survive a specimen
// file, a removal of balls and the scene/results.json round trip. All units SI (rad, rad/s, s).
#include "helpers.hpp"
#include "io/json_input.hpp"
#include "io/specimen.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;
using namespace rocklab;
using rocklab::test::near_rel;

namespace {

// One ball spinning freely (no contacts, no gravity, no damping), and optionally a second one
// far away spinning at `spin2`.
std::unique_ptr<Model> spinning_ball(int dim, const Vec3& spin, bool track,
                                     const Vec3* spin2 = nullptr) {
  auto m = std::make_unique<Model>();
  m->settings.dim = dim;
  m->settings.local_damping = 0;
  m->settings.timestep = 1e-4;
  const std::size_t b = m->balls.add(dim, 1, Vec3::Zero(), 0.01, 2600, m->group_index("rock"));
  m->balls.spin[b] = spin;
  m->balls.vel[b] = dim == 2 ? Vec3(0.2, -0.1, 0) : Vec3(0.2, -0.1, 0.05);
  if (spin2)
    m->balls.spin[m->balls.add(dim, 2, Vec3(1, 0, 0), 0.01, 2600, 0)] = *spin2;
  m->balls.track_orientation(track);
  m->initialize();
  return m;
}

} // namespace

TEST(Orientation, AFreeSpinTurnsTheBallByOmegaT) {
  // 2D: the signed angle about z is omega t (1.5 rad after 5,000 steps of 1e-4 s at 3 rad/s).
  auto m2 = spinning_ball(2, Vec3(0, 0, 3), true);
  m2->cycle(5000);
  EXPECT_TRUE(near_rel(rotation_vector(m2->balls.orient[0]).z(), 3 * m2->time(), 1e-10));
  EXPECT_TRUE(near_rel(m2->time(), 0.5, 1e-12));
  auto back = spinning_ball(2, Vec3(0, 0, -2), true); // the other way: a negative angle
  back->cycle(5000);
  EXPECT_TRUE(near_rel(rotation_vector(back->balls.orient[0]).z(), -1.0, 1e-10));
  // 3D about an oblique axis: the rotation vector is omega t (|omega| t = 1.5 rad).
  const Vec3 w = Vec3(1, 2, -2) * 0.5;
  auto m3 = spinning_ball(3, w, true);
  m3->cycle(10000);
  EXPECT_TRUE(near_rel((rotation_vector(m3->balls.orient[0]) - w * m3->time()).norm(), 0, 1e-10,
                       w.norm() * m3->time()))
      << rotation_vector(m3->balls.orient[0]).transpose();
  EXPECT_NEAR(m3->balls.orient[0].norm(), 1.0, 1e-14);
  // Tracking is bookkeeping only: the same run without it moves the ball bit for bit the same.
  auto off = spinning_ball(3, w, false);
  off->cycle(10000);
  EXPECT_TRUE(off->balls.orient.empty());
  EXPECT_EQ(off->balls.pos[0], m3->balls.pos[0]);
  EXPECT_EQ(off->balls.spin[0], m3->balls.spin[0]);
}

TEST(Orientation, PebblesTurnWithTheirClumpAndRotatedModelsGiveRotatedRotations) {
  // A tumbling asymmetric clump (its spin axis precesses): each pebble's arm from the centroid
  // is its orientation applied to the starting arm.
  auto run = [](const Eigen::Matrix3d& R) {
    auto m = std::make_unique<Model>();
    m->settings.dim = 3;
    m->settings.local_damping = 0;
    m->settings.timestep = 1e-5;
    // Pebbles apart, so that the mass properties are exact (overlaps are integrated on an
    // axis-aligned grid, which a rotation changes slightly).
    const std::vector<Pebble> p{{R * Vec3(0, 0, 0), 0.05},
                                {R * Vec3(0.12, 0, 0), 0.04},
                                {R * Vec3(0.02, 0.1, 0), 0.03},
                                {R * Vec3(0.03, 0.02, 0.1), 0.025}};
    m->add_clump(p, 2600, m->group_index("rock"), 1, 1, R * Vec3(0.1, 0, 0), R * Vec3(3, -5, 7));
    const std::size_t loose = m->balls.add(3, 9, R * Vec3(1, 1, 1), 0.02, 2600, 0);
    m->balls.spin[loose] = R * Vec3(0, 4, 1);
    m->balls.track_orientation(true);
    m->initialize();
    return m;
  };
  auto m = run(Eigen::Matrix3d::Identity());
  const Clump& c = m->clumps[0];
  std::vector<Vec3> arm0;
  for (std::int32_t i : c.pebbles)
    arm0.push_back(m->balls.pos[static_cast<std::size_t>(i)] - c.pos);
  m->cycle(30000); // 0.3 s: several radians of tumbling
  for (std::size_t a = 0; a < c.pebbles.size(); ++a) {
    const std::size_t i = static_cast<std::size_t>(c.pebbles[a]);
    EXPECT_TRUE(near_rel((m->balls.orient[i] * arm0[a] - (m->balls.pos[i] - c.pos)).norm(), 0, 1e-9,
                         arm0[a].norm()))
        << a;
  }
  EXPECT_GT(rotation_vector(m->balls.orient[0]).norm(), 0.5);
  // The same model turned by R: every rotation vector is R times the original one.
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Vec3(1, -2, 0.5).normalized()).toRotationMatrix();
  auto r = run(R);
  r->cycle(30000);
  for (std::size_t i = 0; i < m->balls.size(); ++i)
    EXPECT_TRUE(near_rel(
        (rotation_vector(r->balls.orient[i]) - R * rotation_vector(m->balls.orient[i])).norm(), 0,
        1e-9, 1.0))
        << i << ": " << rotation_vector(r->balls.orient[i]).transpose() << " vs "
        << (R * rotation_vector(m->balls.orient[i])).transpose() << " pos "
        << (r->balls.pos[i] - R * m->balls.pos[i]).norm();
}

TEST(Orientation, SurvivesSpecimenFilesAndRemovalAndOlderFilesLoadWithoutIt) {
  const Vec3 spin2(-3, 0, 1);
  auto m = spinning_ball(3, Vec3(1, 2, 3), true, &spin2);
  m->cycle(200);
  const fs::path file = test::scratch_root() / "rocklab-orientation.rlspec";
  save_model(*m, file.string());
  std::unique_ptr<Model> b = load_model(file.string());
  ASSERT_TRUE(b->balls.tracks_orientation());
  ASSERT_EQ(b->balls.orient.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i)
    EXPECT_EQ(b->balls.orient[i].coeffs(), m->balls.orient[i].coeffs()) << i;
  m->cycle(100), b->cycle(100);
  EXPECT_EQ(b->balls.orient[1].coeffs(), m->balls.orient[1].coeffs());
  // Removing a ball keeps the others' orientations with them.
  const Eigen::Quaterniond second = m->balls.orient[1];
  m->remove_balls({true, false});
  ASSERT_EQ(m->balls.orient.size(), 1u);
  EXPECT_EQ(m->balls.orient[0].coeffs(), second.coeffs());
  // A version-6 file (written before orientations: no tracking flag at the end of the body)
  // still loads, as a model without tracking.
  auto plain = spinning_ball(2, Vec3(0, 0, 1), false);
  save_model(*plain, file.string());
  const std::string bytes = test::read_file(file);
  const std::size_t eol = bytes.find('\n');
  nlohmann::json header = nlohmann::json::parse(bytes.substr(0, eol));
  std::string body = bytes.substr(eol + 1);
  // Version 8 ends with the density-scaling factors: two empty arrays (a 64-bit zero count each).
  ASSERT_GE(body.size(), 17u);
  ASSERT_EQ(body.substr(body.size() - 16), std::string(16, '\0'));
  body.resize(body.size() - 16);
  ASSERT_EQ(body.back(), '\0'); // the tracking flag, off
  body.pop_back();
  header["version"] = 6;
  header["body_bytes"] = body.size();
  header["body_fnv1a64"] = text_hash(body);
  std::ofstream(file, std::ios::binary) << header.dump() << '\n' << body;
  std::unique_ptr<Model> old = load_model(file.string());
  EXPECT_FALSE(old->balls.tracks_orientation());
  EXPECT_EQ(old->balls.pos[0], plain->balls.pos[0]);
}

TEST(Orientation, ScenesReportItInResultsJsonOnlyWhenAsked) {
  // A 2D ball spun at 2 rad/s for 0.5 s: results.json gives its orientation as 1 rad.
  const fs::path dir = test::scratch_root() / "orientation-scene";
  fs::remove_all(dir);
  fs::create_directories(dir);
  nlohmann::json scene = {
      {"units", "SI"},
      {"dimension", 2},
      {"local_damping", 0},
      {"timestep", 1e-4},
      {"orientation_tracking", true},
      {"contact_models", nlohmann::json::array()},
      {"balls",
       {{{"id", 1}, {"position", {0, 0}}, {"radius", 0.01}, {"density", 2600}, {"spin", 2}}}},
      {"run", {{"cycles", 5000}}}};
  const std::string path = (dir / "spin.json").string();
  std::ofstream(path) << scene.dump();
  std::string out;
  ASSERT_EQ(
      test::run_command(test::binary() + " run " + path + " -o " + (dir / "out").string(), &out), 0)
      << out;
  nlohmann::json res = nlohmann::json::parse(std::ifstream(dir / "out" / "results.json"));
  EXPECT_TRUE(near_rel(res["balls"][0]["orientation"].get<double>(), 1.0, 1e-10))
      << res["balls"][0];
  // Without the key nothing is tracked and nothing is written.
  scene.erase("orientation_tracking");
  std::ofstream(path) << scene.dump();
  ASSERT_EQ(
      test::run_command(test::binary() + " run " + path + " -o " + (dir / "out2").string(), &out),
      0)
      << out;
  res = nlohmann::json::parse(std::ifstream(dir / "out2" / "results.json"));
  EXPECT_FALSE(res["balls"][0].contains("orientation"));
  // A value that is not a flag is an input error naming the key.
  scene["orientation_tracking"] = "on";
  std::ofstream(path) << scene.dump();
  EXPECT_EQ(
      test::run_command(test::binary() + " run " + path + " -o " + (dir / "out3").string(), &out),
      2)
      << out;
  EXPECT_NE(out.find("orientation_tracking"), std::string::npos) << out;
}
