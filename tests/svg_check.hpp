// Reading a plot back: the tick labels of an SVG written by viz/svg_plots (class "xtick",
// "ytick", "y2tick") with their positions, checked to be round numbers placed where their value
// is, and a plot's polylines. Used by the plot tests and the lab tests.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace rocklab::test {

struct SvgTick {
  double pos = 0;   ///< x (for x ticks) or y (for y ticks) in SVG pixels
  double value = 0; ///< the printed label, parsed
  std::string text;
};

inline std::vector<SvgTick> svg_ticks(const std::string& svg, const std::string& cls) {
  std::vector<SvgTick> t;
  const std::regex re("<text class=\"" + cls +
                      "\" x=\"([-0-9.]+)\" y=\"([-0-9.]+)\"[^>]*>([^<]*)</text>");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), re); it != std::sregex_iterator();
       ++it) {
    const double x = std::stod((*it)[1]), y = std::stod((*it)[2]);
    t.push_back({cls == "xtick" ? x : y - 4, std::stod((*it)[3]), (*it)[3]});
  }
  return t;
}

/// The ticks of one axis: at least two; equally spaced in value (a round step: 1, 2, 2.5 or 5
/// times a power of ten) and in position; every label the exact multiple of the step it stands
/// for (so "-0.35" is never printed "-0.4"); 0 present when the axis spans it; no "-0".
inline ::testing::AssertionResult ticks_are_true(const std::string& svg, const std::string& cls) {
  const auto t = svg_ticks(svg, cls);
  if (t.size() < 2)
    return ::testing::AssertionFailure() << cls << ": " << t.size() << " ticks";
  const double step = t[1].value - t[0].value;
  const double dpos = (t.back().pos - t.front().pos) / static_cast<double>(t.size() - 1);
  const double mag = std::pow(10, std::floor(std::log10(std::abs(step))));
  const double f = std::abs(step) / mag;
  bool round = false;
  for (double r : {1.0, 2.0, 2.5, 5.0, 10.0})
    round = round || std::abs(f - r) < 1e-6;
  if (!round)
    return ::testing::AssertionFailure() << cls << ": step " << step << " is not round";
  bool zero = false;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const double k = (t[i].value - t[0].value) / step;
    if (std::abs(k - static_cast<double>(i)) > 1e-6)
      return ::testing::AssertionFailure()
             << cls << ": label " << t[i].text << " is not tick 0 + " << i << " steps of " << step;
    if (std::abs(t[i].pos - (t[0].pos + static_cast<double>(i) * dpos)) > 0.02)
      return ::testing::AssertionFailure()
             << cls << ": label " << t[i].text << " at " << t[i].pos << " is not equally spaced";
    if (std::abs(t[i].value / step - std::round(t[i].value / step)) > 1e-6)
      return ::testing::AssertionFailure()
             << cls << ": label " << t[i].text << " is not a multiple of the step " << step;
    if (t[i].text.rfind("-0", 0) == 0 && t[i].value == 0)
      return ::testing::AssertionFailure() << cls << ": label " << t[i].text;
    zero = zero || t[i].value == 0;
  }
  if (t.front().value < 0 && t.back().value > 0 && !zero)
    return ::testing::AssertionFailure() << cls << ": spans 0 without a 0 tick";
  return ::testing::AssertionSuccess();
}

/// The value an SVG position stands for on an axis, from its first and last tick.
inline double svg_axis_value(const std::vector<SvgTick>& t, double pos) {
  return t.front().value + (pos - t.front().pos) / (t.back().pos - t.front().pos) *
                               (t.back().value - t.front().value);
}

/// The points of each polyline, in SVG pixels. (Read without std::regex: libstdc++'s recursive
/// matcher overflows the stack on a polyline of thousands of points.)
inline std::vector<std::vector<std::pair<double, double>>> svg_polylines(const std::string& svg) {
  std::vector<std::vector<std::pair<double, double>>> out;
  for (std::size_t at = svg.find("<polyline"); at != std::string::npos;
       at = svg.find("<polyline", at + 1)) {
    const std::size_t end = svg.find('>', at);
    const std::size_t pts = svg.find(" points=\"", at);
    if (pts == std::string::npos || pts > end)
      continue;
    std::istringstream in(svg.substr(pts + 9, svg.find('"', pts + 9) - pts - 9));
    out.emplace_back();
    double x = 0, y = 0;
    char comma = 0;
    while (in >> x >> comma >> y && comma == ',')
      out.back().emplace_back(x, y);
  }
  return out;
}

} // namespace rocklab::test
