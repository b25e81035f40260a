#include "viz/svg_plots.hpp"

#include "viz/polyline_thin.hpp"
#include "viz/svg_text.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace rocklab {

namespace {

constexpr std::size_t kThinAbove = 2000; ///< series with more points are thinned (0.05 px)

using svg::escape;
using svg::num;

// A "nice" tick step for a range.
double tick_step(double span) {
  if (!(span > 0))
    return 1;
  const double raw = span / 5;
  const double mag = std::pow(10, std::floor(std::log10(raw)));
  for (double f : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (f * mag >= raw)
      return f * mag;
  return 10 * mag;
}

// The decimals that print every multiple of `step` exactly (0.25 needs 2, 0.5 needs 1, 20 none).
int tick_digits(double step) {
  for (int d = 0; d < 9; ++d) {
    const double scaled = step * std::pow(10.0, d);
    if (std::abs(scaled - std::round(scaled)) < 1e-6 * scaled)
      return d;
  }
  return 9;
}

std::string tick_label(double v, int digits) {
  char b[32];
  std::snprintf(b, sizeof b, "%.*f", digits, v);
  std::string t = b;
  if (t.find_first_not_of("-0.") == std::string::npos)
    t = t.substr(t[0] == '-' ? 1 : 0); // no "-0.00"
  return t;
}

// An axis: its limits are whole multiples of its tick step, and its ticks are the multiples k *
// step between them (computed from k, so no drift and no tick off the grid).
// On a log axis the values are log10 of the data: the ticks fall on whole decades and are labelled
// with the data value (0.01, 0.1, 1, 10, ...).
struct Range1 {
  double lo = 1e300, hi = -1e300, step = 1;
  bool log = false;
  bool whole = false; ///< ticks on whole numbers only (a count: evaluations, seeds)
  void add(double v) {
    if (std::isfinite(v)) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  void finish() {
    if (lo > hi)
      lo = 0, hi = 1;
    if (hi - lo <= 0)
      hi = lo + 1;
    step = log ? std::max(1.0, std::ceil((hi - lo) / 8 - 1e-9)) : tick_step(hi - lo);
    if (whole)
      step = std::max(1.0, std::round(step));
    lo = std::floor(lo / step + 1e-9) * step;
    hi = std::ceil(hi / step - 1e-9) * step;
  }
  /// (value, label) of every tick
  std::vector<std::pair<double, std::string>> ticks() const {
    std::vector<std::pair<double, std::string>> t;
    const long k0 = std::lround(lo / step), k1 = std::lround(hi / step);
    const int digits = tick_digits(step);
    for (long k = k0; k <= k1; ++k) {
      const double v = static_cast<double>(k) * step;
      if (!log)
        t.emplace_back(v, tick_label(v, digits));
      else if (std::abs(v) <= 4)
        t.emplace_back(v, tick_label(std::pow(10.0, v), v < 0 ? static_cast<int>(-v) : 0));
      else
        t.emplace_back(v, "1e" + std::to_string(std::lround(v)));
    }
    return t;
  }
};

} // namespace

namespace {

// Where a line plot draws: the plot area [L, L + pw] x [T, T + ph] and the axes' mappings.
struct PlotFrame {
  double W = 760, H = 480, L = 80, R = 30, T = 50, B = 60;
  Range1 rx, ry, ry2;
  double pw() const { return W - L - R; }
  double ph() const { return H - T - B; }
  double X(double v) const { return L + (v - rx.lo) / (rx.hi - rx.lo) * pw(); }
  double Y(double v, bool right) const {
    const Range1& r = right ? ry2 : ry;
    return T + ph() - (v - r.lo) / (r.hi - r.lo) * ph();
  }
};

struct LegendBox {
  double x = 0, y = 0, w = 0, h = 0;
  bool above = false; ///< in a band above the plot area (no free corner inside it)
};

// Whether the segment (x0, y0)-(x1, y1) meets the box (Liang-Barsky clipping).
bool segment_meets_box(double x0, double y0, double x1, double y1, const LegendBox& b) {
  double t0 = 0, t1 = 1;
  const double dx = x1 - x0, dy = y1 - y0;
  const double p[4] = {-dx, dx, -dy, dy};
  const double q[4] = {x0 - (b.x - 4), b.x + b.w + 4 - x0, y0 - (b.y - 4), b.y + b.h + 4 - y0};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0) {
      if (q[i] < 0)
        return false;
      continue;
    }
    const double t = q[i] / p[i];
    if (p[i] < 0)
      t0 = std::max(t0, t);
    else
      t1 = std::min(t1, t);
    if (t0 > t1)
      return false;
  }
  return true;
}

// Width of a label in the plots' 12 px sans-serif: about 7 px a character (the legend box, the
// markers' clearance and the stacking of marker labels all use this estimate).
double text_width(std::size_t chars) {
  return 7.0 * static_cast<double>(chars);
}

// A marker's label goes to the left of its circle when on the right it would cross the plot
// area's right edge (into the right axis' tick labels).
bool label_left_of(const PlotFrame& f, double x, const std::string& label) {
  return x + 6 + text_width(label.size()) > f.L + f.pw();
}

// How many drawn segments, points and marker labels meet a box.
std::size_t points_inside(const PlotFrame& f, const std::vector<PlotSeries>& series,
                          const std::vector<PlotMarker>& markers, const LegendBox& b) {
  std::size_t n = 0;
  for (const PlotSeries& p : series) {
    double px = NAN, py = NAN;
    for (std::size_t i = 0; i < p.x.size() && i < p.y.size(); ++i) {
      if (!std::isfinite(p.x[i]) || !std::isfinite(p.y[i]))
        continue;
      const double x = f.X(p.x[i]), y = f.Y(p.y[i], p.right_axis);
      n += segment_meets_box(std::isfinite(px) ? px : x, std::isfinite(py) ? py : y, x, y, b);
      px = x, py = y;
    }
  }
  for (const PlotMarker& m : markers) {
    const double x = f.X(m.x), y = f.Y(m.y, false);
    const double w = 10 + text_width(m.label.size()); // the circle and its label
    const bool right = label_left_of(f, x, m.label);
    const double mx0 = right ? x - w : x - 4, mx1 = right ? x + 4 : x + w;
    n += mx0 < b.x + b.w + 4 && mx1 > b.x - 4 && y - 18 < b.y + b.h + 4 && y + 4 > b.y - 4;
  }
  return n;
}

// The legend goes into the corner of the plot area with no data; when every corner has data, into
// a band above the plot area.
LegendBox place_legend(PlotFrame& f, const std::vector<PlotSeries>& series,
                       const std::vector<PlotMarker>& markers) {
  std::size_t chars = 0;
  for (const PlotSeries& p : series)
    chars = std::max(chars, p.label.size());
  LegendBox b;
  b.w = 44 + text_width(chars), b.h = 16.0 * static_cast<double>(series.size());
  if (series.empty())
    return b;
  for (int corner = 0; corner < 4; ++corner) {
    b.x = corner % 2 == 0 ? f.L + 8 : f.L + f.pw() - 8 - b.w;
    b.y = corner < 2 ? f.T + 6 : f.T + f.ph() - 6 - b.h;
    if (points_inside(f, series, markers, b) == 0)
      return b;
  }
  b.above = true, b.x = f.L + 8, b.y = f.T;
  f.T += b.h + 6; // the picture grows; the plot area keeps its size
  f.H += b.h + 6;
  return b;
}

std::string axes_svg(const PlotFrame& f, bool has2) {
  std::string s;
  for (const auto& [v, label] : f.rx.ticks()) {
    s += "<line x1=\"" + num(f.X(v)) + "\" y1=\"" + num(f.T) + "\" x2=\"" + num(f.X(v)) +
         "\" y2=\"" + num(f.T + f.ph()) + "\" stroke=\"#e0e0e0\"/>\n";
    s += "<text class=\"xtick\" x=\"" + num(f.X(v)) + "\" y=\"" + num(f.T + f.ph() + 16) +
         "\" text-anchor=\"middle\">" + label + "</text>\n";
  }
  for (const auto& [v, label] : f.ry.ticks()) {
    s += "<line x1=\"" + num(f.L) + "\" y1=\"" + num(f.Y(v, false)) + "\" x2=\"" +
         num(f.L + f.pw()) + "\" y2=\"" + num(f.Y(v, false)) + "\" stroke=\"#e0e0e0\"/>\n";
    s += "<text class=\"ytick\" x=\"" + num(f.L - 6) + "\" y=\"" + num(f.Y(v, false) + 4) +
         "\" text-anchor=\"end\">" + label + "</text>\n";
  }
  if (has2)
    for (const auto& [v, label] : f.ry2.ticks())
      s += "<text class=\"y2tick\" x=\"" + num(f.L + f.pw() + 6) + "\" y=\"" +
           num(f.Y(v, true) + 4) + "\">" + label + "</text>\n";
  s += "<rect x=\"" + num(f.L) + "\" y=\"" + num(f.T) + "\" width=\"" + num(f.pw()) +
       "\" height=\"" + num(f.ph()) + "\" fill=\"none\" stroke=\"black\"/>\n";
  return s;
}

std::string dash(const PlotSeries& p) {
  return p.dashed ? " stroke-dasharray=\"6,4\"" : "";
}

// A log left axis plots log10 of the data: the left-axis series (returned), the markers and y_top
// are mapped; a value <= 0 has no place on it (NaN: not drawn; a marker there later sits on the
// axis' bottom).
std::vector<PlotSeries> to_log_axis(const std::vector<PlotSeries>& series,
                                    std::vector<PlotMarker>& markers, double& y_top) {
  auto lg = [](double v) { return v > 0 ? std::log10(v) : NAN; };
  std::vector<PlotSeries> logged = series;
  for (PlotSeries& p : logged)
    if (!p.right_axis)
      std::transform(p.y.begin(), p.y.end(), p.y.begin(), lg);
  for (PlotMarker& m : markers)
    m.y = lg(m.y);
  y_top = lg(y_top);
  return logged;
}

// One series as a polyline (SVG pixels), or as a dot when it has a single finite point.
std::string series_svg(const PlotFrame& f, const PlotSeries& p) {
  std::vector<std::array<double, 2>> xy;
  for (std::size_t i = 0; i < p.x.size() && i < p.y.size(); ++i)
    if (std::isfinite(p.x[i]) && std::isfinite(p.y[i]))
      xy.push_back({f.X(p.x[i]), f.Y(p.y[i], p.right_axis)});
  const std::size_t drawn = xy.size();
  // A dense series (a 10k-grain test's curve: ~40k samples, hundreds per pixel column) drawn
  // through the points that keep it within 0.05 px of every sample: a 2.7 MB SVG became 33 kB
  // (its rendering had been the largest allocation at the test's end).
  std::string pts;
  auto add = [&](const std::array<double, 2>& q) { pts += num(q[0]) + "," + num(q[1]) + " "; };
  if (drawn > kThinAbove)
    for (std::size_t i : thin_polyline(xy, 0.05))
      add(xy[i]);
  else
    for (const auto& q : xy)
      add(q);
  std::string s = "<polyline fill=\"none\" stroke=\"" + p.color + "\" stroke-width=\"1.6\"" +
                  dash(p) + " points=\"" + pts + "\"/>\n";
  // A series with one point draws no line: a dot shows it (a calibration target measured only by
  // the final evaluation was invisible on the convergence plot).
  if (drawn == 1)
    s += "<circle class=\"point\" cx=\"" + num(xy[0][0]) + "\" cy=\"" + num(xy[0][1]) +
         "\" r=\"4\" fill=\"" + p.color + "\"/>\n";
  return s;
}

} // namespace

std::string line_plot_svg(const std::string& title, const std::string& xlabel,
                          const std::string& ylabel, const std::string& y2label,
                          const std::vector<PlotSeries>& series_in,
                          const std::vector<PlotMarker>& markers_in, double y_top, bool log_y,
                          bool whole_x) {
  std::vector<PlotSeries> logged;
  std::vector<PlotMarker> markers = markers_in;
  if (log_y)
    logged = to_log_axis(series_in, markers, y_top);
  const std::vector<PlotSeries>& series = log_y ? logged : series_in;
  PlotFrame f;
  f.ry.log = log_y;
  f.rx.whole = whole_x;
  f.R = y2label.empty() ? 30 : 80;
  bool has2 = false;
  for (const PlotSeries& p : series)
    for (std::size_t i = 0; i < p.x.size() && i < p.y.size(); ++i) {
      f.rx.add(p.x[i]);
      (p.right_axis ? f.ry2 : f.ry).add(p.y[i]);
      has2 = has2 || p.right_axis;
    }
  if (std::isfinite(y_top))
    f.ry.add(y_top);
  f.rx.finish(), f.ry.finish(), f.ry2.finish();
  for (PlotMarker& m : markers)
    if (!std::isfinite(m.y))
      m.y = f.ry.lo;
  const LegendBox lg = place_legend(f, series, markers);
  std::string s = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + num(f.W) + "\" height=\"" +
                  num(f.H) + "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  s += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  s += "<text x=\"" + num(f.W / 2) + "\" y=\"24\" text-anchor=\"middle\" font-size=\"15\">" +
       escape(title) + "</text>\n";
  s += axes_svg(f, has2);
  s += "<text x=\"" + num(f.L + f.pw() / 2) + "\" y=\"" + num(f.H - 18) +
       "\" text-anchor=\"middle\">" + escape(xlabel) + "</text>\n";
  s += "<text transform=\"translate(18," + num(f.T + f.ph() / 2) +
       ") rotate(-90)\" text-anchor=\"middle\">" + escape(ylabel) + "</text>\n";
  if (has2)
    s += "<text transform=\"translate(" + num(f.W - 14) + "," + num(f.T + f.ph() / 2) +
         ") rotate(90)\" text-anchor=\"middle\">" + escape(y2label) + "</text>\n";
  double ly = lg.y + 8;
  for (const PlotSeries& p : series) {
    s += series_svg(f, p);
    s += "<line class=\"legend\" x1=\"" + num(lg.x + 2) + "\" y1=\"" + num(ly) + "\" x2=\"" +
         num(lg.x + 26) + "\" y2=\"" + num(ly) + "\" stroke=\"" + p.color +
         "\" stroke-width=\"2\"" + dash(p) + "/>\n";
    s += "<text x=\"" + num(lg.x + 32) + "\" y=\"" + num(ly + 4) + "\">" + escape(p.label) +
         "</text>\n";
    ly += 16;
  }
  // A label that would overlap one already placed (about 7 px per character, 14 px a line) goes a
  // line higher: markers one evaluation apart wrote "strengthratios" on the calibration plot.
  struct Box {
    double x0, x1, y;
  };
  std::vector<Box> placed;
  for (const PlotMarker& m : markers) {
    s += "<circle cx=\"" + num(f.X(m.x)) + "\" cy=\"" + num(f.Y(m.y, false)) +
         "\" r=\"4\" fill=\"none\" stroke=\"black\"/>\n";
    const bool right = label_left_of(f, f.X(m.x), m.label);
    const double x = f.X(m.x) + (right ? -6 : 6), w = text_width(m.label.size());
    const double x0 = right ? x - w : x, x1 = x0 + w;
    double y = f.Y(m.y, false) - 6;
    for (bool moved = true; moved;) {
      moved = false;
      for (const Box& b : placed)
        if (x0 < b.x1 + 3 && b.x0 < x1 + 3 && std::abs(y - b.y) < 13) {
          y = b.y - 14;
          moved = true;
        }
    }
    placed.push_back({x0, x1, y});
    s += "<text x=\"" + num(x) + "\" y=\"" + num(y) + "\"" + (right ? " text-anchor=\"end\"" : "") +
         ">" + escape(m.label) + "</text>\n";
  }
  s += "</svg>\n";
  return s;
}

} // namespace rocklab
