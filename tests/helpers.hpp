// Shared helpers for the test suite: small hand-built models and one tolerance helper.
#pragma once

#include "core/model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>

namespace rocklab::test {

/// A scratch folder of this test process, so concurrent test runs never share files.
inline std::filesystem::path scratch_root() {
  static const std::filesystem::path root = [] {
    const auto p =
        std::filesystem::temp_directory_path() / ("rocklab-tests-" + std::to_string(::getpid()));
    std::filesystem::create_directories(p);
    return p;
  }();
  return root;
}

/// |a - b| <= rel * max(|b|, floor): the one relative-tolerance check used by the tests.
inline ::testing::AssertionResult near_rel(double a, double b, double rel, double floor = 0.0) {
  const double scale = std::max(std::abs(b), floor);
  if (std::abs(a - b) <= rel * scale)
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << a << " vs " << b << ": relative difference " << std::abs(a - b) / scale << " > " << rel;
}

/// A square plane wall (3D) or a segment (2D) through p with normal n.
inline Wall plane_wall(int dim, const Vec3& p, const Vec3& n, double extent,
                       const std::string& name = "plane") {
  return rocklab::plane_wall(dim, name, p, n.normalized(), extent);
}

inline ModelRule linear_rule(bool ball_facet, LinearProps p) {
  ModelRule r;
  r.ball_facet = ball_facet;
  r.props = p;
  return r;
}

/// Two balls of radius R (3D, 2600 kg/m^3) at a and b with every degree of freedom fixed, ball 2
/// moving at v, one rule for every contact: no gravity or damping, dt 1e-6 s; initialized.
inline std::unique_ptr<Model> driven_pair(const Vec3& a, const Vec3& b, double R, const Vec3& v,
                                          const ModelProps& props) {
  auto m = std::make_unique<Model>();
  m->settings.dim = 3;
  m->settings.gravity = Vec3::Zero();
  m->settings.local_damping = 0;
  m->settings.timestep = 1e-6;
  const auto g = m->group_index("rock");
  m->balls.add(3, 1, a, R, 2600, g);
  m->balls.add(3, 2, b, R, 2600, g);
  m->balls.fixity[0] = m->balls.fixity[1] = 0x3f; // every DOF fixed
  m->balls.vel[1] = v;
  ModelRule rule;
  rule.props = props;
  m->rules.push_back(rule);
  m->initialize();
  return m;
}

inline std::string source_dir() {
  return ROCKLAB_SOURCE_DIR;
}
/// The rocklab executable under test: this build's, or $ROCKLAB_TEST_BINARY (e.g. a copy kept
/// apart while a long fuzz run goes on and the build changes).
inline std::string binary() {
  const char* env = std::getenv("ROCKLAB_TEST_BINARY");
  return env && *env ? env : ROCKLAB_BINARY;
}

inline std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Run a shell command, capturing stderr+stdout into `output`; returns the exit status.
inline int run_command(const std::string& cmd, std::string* output = nullptr) {
  static int counter = 0;
  const std::filesystem::path log =
      rocklab::test::scratch_root() / ("cmd-" + std::to_string(counter++) + ".log");
  const int rc = std::system((cmd + " > " + log.string() + " 2>&1").c_str());
  if (output)
    *output = read_file(log);
  std::filesystem::remove(log);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

} // namespace rocklab::test

#include "io/scene.hpp"

namespace rocklab::test {

/// |a - b| within half a unit of the 4th significant digit of b ("to 4 significant digits").
inline ::testing::AssertionResult four_digits(double a, double b) {
  const double unit = std::pow(10.0, std::floor(std::log10(std::abs(b))) - 3);
  if (std::abs(a - b) <= 0.5 * unit)
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << a << " does not match " << b << " to 4 digits";
}

/// Rotate (and shift) a loaded scene's bodies: positions, velocities, spins, walls, gravity.
inline void transform_model(Model& m, const Eigen::Matrix3d& R, const Vec3& shift) {
  for (std::size_t i = 0; i < m.balls.size(); ++i) {
    m.balls.pos[i] = R * m.balls.pos[i] + shift;
    m.balls.vel[i] = R * m.balls.vel[i];
    m.balls.spin[i] = R * m.balls.spin[i];
  }
  for (Wall& w : m.walls) {
    for (Facet& f : w.facets)
      for (int k = 0; k < f.nv; ++k)
        f.v[k] = R * f.v[k] + shift;
    w.center = R * w.center + shift;
    w.velocity = R * w.velocity;
    w.spin = R * w.spin;
    w.update_bounds();
  }
  m.settings.gravity = R * m.settings.gravity;
}

/// Run every stage of a scene (cycle-count stages) without writing output; returns the model.
inline std::unique_ptr<Model> run_scene_file(const std::string& file,
                                             const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity(),
                                             const Vec3& shift = Vec3::Zero()) {
  Scene s = load_scene(file);
  transform_model(*s.model, R, shift);
  s.model->initialize();
  for (const Stage& st : s.stages) {
    for (const BallChange& bc : st.set) {
      if (bc.velocity)
        s.model->balls.vel[bc.index] = R * *bc.velocity;
      if (bc.spin)
        s.model->balls.spin[bc.index] = R * *bc.spin;
      s.model->balls.fixity[bc.index] =
          static_cast<std::uint8_t>((s.model->balls.fixity[bc.index] | bc.fix) & ~bc.free);
    }
    for (const MethodCall& mc : st.methods)
      s.model->apply_method(mc.model, mc.method, mc.gap_lo, mc.gap_hi, mc.element, mc.gap_ratio);
    EXPECT_GT(st.run.cycles, 0) << "test helper runs cycle-count stages only";
    s.model->cycle(st.run.cycles);
  }
  return std::move(s.model);
}

} // namespace rocklab::test
