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

namespace rocklab::test {

/// |a - b| <= rel * max(|b|, floor): the one relative-tolerance check used by the tests.
inline ::testing::AssertionResult near_rel(double a, double b, double rel, double floor = 0.0) {
  const double scale = std::max(std::abs(b), floor);
  if (std::abs(a - b) <= rel * scale)
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << a << " vs " << b << ": relative difference " << std::abs(a - b) / scale << " > " << rel;
}

/// A square plane wall (3D) or a segment (2D) through p with normal n.
inline Wall plane_wall(int dim, const Vec3& p, const Vec3& n_in, double extent,
                       const std::string& name = "plane") {
  const Vec3 n = n_in.normalized();
  Wall w;
  w.name = name;
  const double h = 0.5 * extent;
  if (dim == 2) {
    const Vec3 u(-n.y(), n.x(), 0);
    Facet f;
    f.nv = 2;
    f.v[0] = p - h * u;
    f.v[1] = p + h * u;
    w.facets.push_back(f);
  } else {
    const Vec3 g = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
    const Vec3 u = (g - g.dot(n) * n).normalized();
    const Vec3 v = n.cross(u);
    Facet a, b;
    a.v = {p - h * u - h * v, p + h * u - h * v, p + h * u + h * v};
    b.v = {p - h * u - h * v, p + h * u + h * v, p - h * u + h * v};
    w.facets = {a, b};
  }
  w.center = p;
  w.update_bounds();
  return w;
}

inline ModelRule linear_rule(bool ball_facet, LinearProps p) {
  ModelRule r;
  r.ball_facet = ball_facet;
  r.props = p;
  return r;
}

inline std::string source_dir() {
  return ROCKLAB_SOURCE_DIR;
}
inline std::string binary() {
  return ROCKLAB_BINARY;
}

inline std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Run a shell command, capturing stderr+stdout into `output`; returns the exit status.
inline int run_command(const std::string& cmd, std::string* output = nullptr) {
  const std::filesystem::path log =
      std::filesystem::temp_directory_path() / ("rocklab-cmd-" + std::to_string(::rand()) + ".log");
  const int rc = std::system((cmd + " > " + log.string() + " 2>&1").c_str());
  if (output)
    *output = read_file(log);
  std::filesystem::remove(log);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

} // namespace rocklab::test
