// Plots read back: tick labels true to their positions, data drawn where the ticks say, the
// legend off the data, a PNG beside each SVG (viz/svg_plots, viz/svg_png).
#include "helpers.hpp"
#include "svg_check.hpp"
#include "viz/polyline_thin.hpp"
#include "viz/svg_plots.hpp"
#include "viz/svg_png.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <regex>

namespace rocklab {
namespace {

// The 3D UCS strain axis that printed -0.35 % as "-0.4" and had no 0 tick (issue 14).
PlotSeries strains() {
  PlotSeries axial{"axial", {}, {}, "#000000"};
  PlotSeries lateral{"lateral", {}, {}, "#1f77b4"};
  for (int i = 0; i <= 50; ++i) {
    const double s = 0.15 * i / 50.0; // axial strain [%]
    axial.x.push_back(s), axial.y.push_back(1000 * s);
    lateral.x.push_back(-0.35 * i / 50.0), lateral.y.push_back(1000 * s);
  }
  return axial;
}

TEST(Plots, TickLabelsAreTheValuesAtTheirPositions) {
  for (const auto& [lo, hi] : std::vector<std::pair<double, double>>{
           {-0.35, 0.15}, {0, 173.2}, {-3.1e-4, 2.2e-3}, {12, 12.00001}, {-1, -0.2}, {0, 1e9}}) {
    PlotSeries s{"data", {}, {}, "#000000"};
    for (int i = 0; i <= 40; ++i) {
      const double x = lo + (hi - lo) * i / 40.0;
      s.x.push_back(x), s.y.push_back(0.5 * x * x - x);
    }
    const std::string svg = line_plot_svg("t", "x", "y", "", {s, strains()});
    EXPECT_TRUE(test::ticks_are_true(svg, "xtick")) << lo << " .. " << hi;
    EXPECT_TRUE(test::ticks_are_true(svg, "ytick")) << lo << " .. " << hi;
    // Each data point is drawn where the axes' tick labels say it is.
    const auto xt = test::svg_ticks(svg, "xtick"), yt = test::svg_ticks(svg, "ytick");
    const auto lines = test::svg_polylines(svg);
    ASSERT_EQ(lines.size(), 2u);
    ASSERT_EQ(lines[0].size(), s.x.size());
    const double xspan = xt.back().value - xt.front().value;
    const double yspan = yt.back().value - yt.front().value;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      EXPECT_NEAR(test::svg_axis_value(xt, lines[0][i].first), s.x[i], 2e-4 * xspan);
      EXPECT_NEAR(test::svg_axis_value(yt, lines[0][i].second), s.y[i], 2e-4 * yspan);
    }
  }
  // the case of the issue: ticks -0.4 ... 0.2 by 0.1 (or coarser), with a 0 tick
  PlotSeries lateral{"lateral", {-0.35, 0}, {0, 100}, "#1f77b4"};
  PlotSeries axial{"axial", {0, 0.15}, {0, 100}, "#000000"};
  const std::string svg = line_plot_svg("t", "strain [%]", "stress [MPa]", "", {axial, lateral});
  bool zero = false;
  for (const auto& t : test::svg_ticks(svg, "xtick"))
    zero = zero || t.text == "0" || t.text == "0.0" || t.text == "0.00";
  EXPECT_TRUE(zero);
}

// Distance of (x, y) from the polyline.
double distance_to(const std::vector<std::pair<double, double>>& line, double x, double y) {
  double best = INFINITY;
  for (std::size_t i = 0; i + 1 < line.size(); ++i) {
    const auto [ax, ay] = line[i];
    const auto [bx, by] = line[i + 1];
    const double dx = bx - ax, dy = by - ay, l2 = dx * dx + dy * dy;
    const double t = l2 > 0 ? std::clamp(((x - ax) * dx + (y - ay) * dy) / l2, 0.0, 1.0) : 0.0;
    best = std::min(best, std::hypot(x - ax - t * dx, y - ay - t * dy));
  }
  return best;
}

TEST(Plots, ADenseCurveIsDrawnThroughFewerPointsWithinATwentiethOfAPixel) {
  // thin_polyline: the ends kept, a straight run reduced to its ends, a zigzag above the
  // tolerance kept whole, and every dropped point within the tolerance of the kept line.
  std::vector<std::array<double, 2>> straight, zigzag;
  for (int i = 0; i <= 100; ++i) {
    straight.push_back({i * 1.0, 2.0 * i});
    zigzag.push_back({i * 1.0, i % 2 ? 0.2 : 0.0});
  }
  EXPECT_EQ(thin_polyline(straight, 0.05), (std::vector<std::size_t>{0, 100}));
  EXPECT_EQ(thin_polyline(zigzag, 0.05).size(), zigzag.size());
  EXPECT_EQ(thin_polyline(zigzag, 0.3), (std::vector<std::size_t>{0, 100}));
  // A stress-strain curve of 40,000 samples with a jittery post-peak branch (0.1 MPa) and a lateral
  // strain that turns back (a volumetric reversal): far fewer points, each sample within 0.05 px of
  // the drawn line (+ the rounding of the two-decimal coordinates and tick positions).
  PlotSeries axial{"axial", {}, {}, "#000000"}, vol{"volumetric", {}, {}, "#2ca02c", true};
  std::uint64_t state = 12345;
  auto noise = [&] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) / 9007199254740992.0 - 0.5;
  };
  for (int i = 0; i < 40000; ++i) {
    const double e = 0.4 * i / 40000.0; // axial strain [%]
    const double s = e < 0.29 ? 160 * std::sin(e / 0.29 * 1.5707963) : 160 - 600 * (e - 0.29);
    axial.x.push_back(e), axial.y.push_back(s + (e > 0.29 ? 0.1 * noise() : 0));
    vol.x.push_back(e - 0.5 * e * e / 0.29), vol.y.push_back(s);
  }
  const std::string svg = line_plot_svg("t", "strain [%]", "stress [MPa]", "", {axial, vol});
  const auto lines = test::svg_polylines(svg);
  ASSERT_EQ(lines.size(), 2u);
  const auto xt = test::svg_ticks(svg, "xtick"), yt = test::svg_ticks(svg, "ytick");
  for (std::size_t k = 0; k < 2; ++k) {
    const PlotSeries& p = k == 0 ? axial : vol;
    EXPECT_LT(lines[k].size(), p.x.size() / 10) << p.label;
    EXPECT_GT(lines[k].size(), 20u) << p.label;
    // pixel positions of the samples from the axes' own ticks
    auto px = [&](const std::vector<test::SvgTick>& t, double v) {
      return t.front().pos + (v - t.front().value) * (t.back().pos - t.front().pos) /
                                 (t.back().value - t.front().value);
    };
    double worst = 0;
    for (std::size_t i = 0; i < p.x.size(); i += 7)
      worst = std::max(worst, distance_to(lines[k], px(xt, p.x[i]), px(yt, p.y[i])));
    EXPECT_LT(worst, 0.065) << p.label;
  }
  EXPECT_LT(svg.size(), 200000u);
}

TEST(Plots, TheLegendIsDrawnOffTheData) {
  // Data filling the top-left corner (a stress-strain curve) and one filling everything.
  PlotSeries rising{"rising", {}, {}, "#000000"};
  for (int i = 0; i <= 100; ++i)
    rising.x.push_back(i), rising.y.push_back(i);
  PlotSeries everywhere{"zigzag", {}, {}, "#d62728"};
  for (int i = 0; i <= 100; ++i)
    everywhere.x.push_back(i), everywhere.y.push_back(i % 2 ? 100 : 0);
  for (const auto& series : std::vector<std::vector<PlotSeries>>{{rising}, {rising, everywhere}}) {
    const std::string svg = line_plot_svg("t", "x", "y", "", series);
    const std::regex re("<line class=\"legend\" x1=\"([-0-9.]+)\" y1=\"([-0-9.]+)\" "
                        "x2=\"([-0-9.]+)\"");
    std::smatch m;
    ASSERT_TRUE(std::regex_search(svg, m, re));
    const double lx = std::stod(m[1]), ly = std::stod(m[2]);
    const double lw = 32 + 7 * 7, lh = 16 * static_cast<double>(series.size());
    for (const auto& line : test::svg_polylines(svg))
      for (std::size_t i = 1; i < line.size(); ++i)
        for (int k = 0; k <= 20; ++k) {
          const double x = line[i - 1].first + (line[i].first - line[i - 1].first) * k / 20.0;
          const double y = line[i - 1].second + (line[i].second - line[i - 1].second) * k / 20.0;
          EXPECT_FALSE(x > lx && x < lx + lw && y > ly - 8 && y < ly - 8 + lh)
              << "data at (" << x << ", " << y << ") under the legend";
        }
  }
}

TEST(Plots, APngIsWrittenBesideEachSvg) {
  const auto dir = test::scratch_root() / "plots_png";
  std::filesystem::create_directories(dir);
  const auto [svg, png] =
      write_svg_and_png(dir / "curve.svg", line_plot_svg("t", "x", "y", "", {strains()}));
  EXPECT_EQ(svg, "curve.svg");
  EXPECT_EQ(png, "curve.png");
  const auto [w, h] = png_size(dir / "curve.png");
  EXPECT_EQ(w, 2 * 760); // twice the SVG's pixel size
  EXPECT_EQ(h, 2 * 480);
  // The PNG is not blank: its compressed size grows with what is drawn on it.
  EXPECT_GT(std::filesystem::file_size(dir / "curve.png"), 10000u);
  EXPECT_THROW(write_png_of_svg("<svg", dir / "bad.png"), std::runtime_error);
}

TEST(Plots, MarkerLabelsThatWouldOverlapAreStacked) {
  // Stage markers of a calibration one evaluation apart: each label keeps its own line.
  PlotSeries s{"e", {1, 2, 3, 4, 15}, {1, 2, 3, 2, 1}, "#000000", false};
  const std::vector<PlotMarker> marks{{6, 0, "strength"}, {7, 0, "ratios"}, {12, 0, "elastic"}};
  const std::string svg = line_plot_svg("t", "x", "y", "", {s}, marks);
  auto y_of = [&](const std::string& label) {
    const std::size_t at = svg.find(">" + label + "</text>");
    EXPECT_NE(at, std::string::npos) << label;
    const std::size_t y = svg.rfind(" y=\"", at);
    return std::stod(svg.substr(y + 4));
  };
  EXPECT_LE(y_of("ratios"), y_of("strength") - 13); // a line higher: they would overlap
  EXPECT_EQ(y_of("elastic"), y_of("strength"));     // far enough apart: same line
}

TEST(Plots, AMarkerLabelStaysInsideThePlotArea) {
  // The 10k-grain UCS plot: "CI (crack volumetric strain)" at 70 % of the width ran over the
  // right axis' tick labels. A label that would cross the frame's right edge is set to the left.
  PlotSeries s{"axial", {0, 0.3, 0.4}, {0, 160, 80}, "#000000"};
  PlotSeries c{"cracks", {0, 0.4}, {0, 24000}, "#d62728", false, true};
  const std::vector<PlotMarker> marks{{0.28, 75, "CI (crack volumetric strain)"},
                                      {0.05, 30, "CI (crack count)"}};
  const std::string svg = line_plot_svg("t", "strain [%]", "stress [MPa]", "cracks", {s, c}, marks);
  std::smatch frame;
  ASSERT_TRUE(std::regex_search(
      svg, frame,
      std::regex("<rect x=\"([-0-9.]+)\" y=\"[-0-9.]+\" width=\"([-0-9.]+)\"[^>]*fill=\"none\"")));
  const double left = std::stod(frame[1]), right = left + std::stod(frame[2]);
  for (const PlotMarker& m : marks) {
    const std::size_t at = svg.find(">" + m.label + "</text>");
    ASSERT_NE(at, std::string::npos) << m.label;
    const std::size_t open = svg.rfind("<text", at);
    const std::string tag = svg.substr(open, at - open);
    const double x = std::stod(tag.substr(tag.find(" x=\"") + 4));
    const double width = 7.0 * static_cast<double>(m.label.size()); // about 7 px a character
    const bool to_left = tag.find("text-anchor=\"end\"") != std::string::npos;
    EXPECT_LE(to_left ? x : x + width, right) << m.label;
    EXPECT_GE(to_left ? x - width : x, left) << m.label;
  }
}

TEST(Plots, ASeriesWithOnePointIsDrawnAsADot) {
  // A target measured only by a calibration's final evaluation has one point and no line.
  PlotSeries one{"bts", {1, 2, 3}, {NAN, NAN, 4}, "#1f77b4", false};
  PlotSeries many{"ucs", {1, 2, 3}, {5, 2, 1}, "#ff7f0e", false};
  const std::string svg = line_plot_svg("t", "x", "y", "", {one, many});
  const std::size_t dot = svg.find("<circle class=\"point\"");
  ASSERT_NE(dot, std::string::npos);
  EXPECT_NE(svg.find("fill=\"#1f77b4\"", dot), std::string::npos);
  EXPECT_EQ(svg.find("<circle class=\"point\"", dot + 1), std::string::npos); // not for "ucs"
}

TEST(Plots, ALogAxisHasDecadeTicksAndKeepsDistantValuesApart) {
  // The calibration's errors in tolerances: 49 (direct tension) and 5.7 (BTS) were one point on a
  // linear axis clipped at 5.
  PlotSeries dt{"dt", {1, 2, 3}, {49.4, 12, 0.5}, "#2ca02c", false};
  PlotSeries bts{"bts", {1, 2, 3}, {5.7, 0.03, 0.2}, "#1f77b4", false};
  const std::vector<PlotMarker> marks{{1, 0, "elastic"}};
  const std::string svg = line_plot_svg("t", "x", "y", "", {dt, bts}, marks, NAN, true);
  const auto yt = test::svg_ticks(svg, "ytick");
  ASSERT_GE(yt.size(), 4u);
  std::vector<std::string> labels;
  for (const auto& t : yt)
    labels.push_back(t.text);
  EXPECT_EQ(labels.front(), "0.01");
  EXPECT_EQ(labels.back(), "100");
  EXPECT_NE(std::find(labels.begin(), labels.end(), "1"), labels.end());
  // equal spacing per decade, and each point at log10 of its value between the ticks
  const double per_decade = yt[0].pos - yt[1].pos;
  for (std::size_t i = 1; i < yt.size(); ++i)
    EXPECT_NEAR(yt[i - 1].pos - yt[i].pos, per_decade, 0.02);
  const auto lines = test::svg_polylines(svg);
  ASSERT_EQ(lines.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    const PlotSeries& p = k == 0 ? dt : bts;
    for (std::size_t i = 0; i < p.y.size(); ++i) {
      const double decades = (yt[0].pos - lines[k][i].second) / per_decade; // above 0.01
      EXPECT_NEAR(std::pow(10.0, decades - 2), p.y[i], 1e-3 * p.y[i]);
    }
  }
  // the marker at 0 sits on the bottom axis
  const std::size_t c = svg.find("<circle cx=");
  ASSERT_NE(c, std::string::npos);
  const std::size_t cy = svg.find("cy=\"", c);
  EXPECT_NEAR(std::stod(svg.substr(cy + 4)), yt[0].pos, 0.02);
}

} // namespace
} // namespace rocklab
