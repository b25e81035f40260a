#include "viz/svg_plots.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace rocklab {

namespace {

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}

std::string escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '<')
      o += "&lt;";
    else if (c == '>')
      o += "&gt;";
    else if (c == '&')
      o += "&amp;";
    else
      o += c;
  }
  return o;
}

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

std::string tick_label(double v, double step) {
  char b[32];
  const int digits = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  std::snprintf(b, sizeof b, "%.*f", std::min(digits, 6), std::abs(v) < 1e-12 * step ? 0.0 : v);
  return b;
}

struct Range1 {
  double lo = 1e300, hi = -1e300;
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
    const double st = tick_step(hi - lo);
    lo = std::floor(lo / st) * st;
    hi = std::ceil(hi / st) * st;
  }
};

} // namespace

std::string line_plot_svg(const std::string& title, const std::string& xlabel,
                          const std::string& ylabel, const std::string& y2label,
                          const std::vector<PlotSeries>& series,
                          const std::vector<PlotMarker>& markers, double y_top) {
  const double W = 760, H = 480, L = 80, R = y2label.empty() ? 30 : 80, T = 50, B = 60;
  Range1 rx, ry, ry2;
  bool has2 = false;
  for (const PlotSeries& s : series)
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      rx.add(s.x[i]);
      (s.right_axis ? ry2 : ry).add(s.y[i]);
      has2 = has2 || s.right_axis;
    }
  rx.finish();
  if (std::isfinite(y_top))
    ry.add(y_top);
  ry.finish();
  ry2.finish();
  const double pw = W - L - R, ph = H - T - B;
  auto X = [&](double v) { return L + (v - rx.lo) / (rx.hi - rx.lo) * pw; };
  auto Y = [&](double v, bool right) {
    const Range1& r = right ? ry2 : ry;
    return T + ph - (v - r.lo) / (r.hi - r.lo) * ph;
  };
  std::string s = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + num(W) + "\" height=\"" +
                  num(H) + "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  s += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  s += "<text x=\"" + num(W / 2) + "\" y=\"24\" text-anchor=\"middle\" font-size=\"15\">" +
       escape(title) + "</text>\n";
  // grid and ticks
  const double sx = tick_step(rx.hi - rx.lo), sy = tick_step(ry.hi - ry.lo);
  for (double v = rx.lo; v <= rx.hi + 1e-9 * sx; v += sx) {
    s += "<line x1=\"" + num(X(v)) + "\" y1=\"" + num(T) + "\" x2=\"" + num(X(v)) + "\" y2=\"" +
         num(T + ph) + "\" stroke=\"#e0e0e0\"/>\n";
    s += "<text x=\"" + num(X(v)) + "\" y=\"" + num(T + ph + 16) + "\" text-anchor=\"middle\">" +
         tick_label(v, sx) + "</text>\n";
  }
  for (double v = ry.lo; v <= ry.hi + 1e-9 * sy; v += sy) {
    s += "<line x1=\"" + num(L) + "\" y1=\"" + num(Y(v, false)) + "\" x2=\"" + num(L + pw) +
         "\" y2=\"" + num(Y(v, false)) + "\" stroke=\"#e0e0e0\"/>\n";
    s += "<text x=\"" + num(L - 6) + "\" y=\"" + num(Y(v, false) + 4) + "\" text-anchor=\"end\">" +
         tick_label(v, sy) + "</text>\n";
  }
  if (has2) {
    const double s2 = tick_step(ry2.hi - ry2.lo);
    for (double v = ry2.lo; v <= ry2.hi + 1e-9 * s2; v += s2)
      s += "<text x=\"" + num(L + pw + 6) + "\" y=\"" + num(Y(v, true) + 4) + "\">" +
           tick_label(v, s2) + "</text>\n";
  }
  s += "<rect x=\"" + num(L) + "\" y=\"" + num(T) + "\" width=\"" + num(pw) + "\" height=\"" +
       num(ph) + "\" fill=\"none\" stroke=\"black\"/>\n";
  s += "<text x=\"" + num(L + pw / 2) + "\" y=\"" + num(H - 18) + "\" text-anchor=\"middle\">" +
       escape(xlabel) + "</text>\n";
  s += "<text transform=\"translate(18," + num(T + ph / 2) +
       ") rotate(-90)\" text-anchor=\"middle\">" + escape(ylabel) + "</text>\n";
  if (has2)
    s += "<text transform=\"translate(" + num(W - 14) + "," + num(T + ph / 2) +
         ") rotate(90)\" text-anchor=\"middle\">" + escape(y2label) + "</text>\n";
  // series and legend
  double ly = T + 14;
  for (const PlotSeries& p : series) {
    std::string pts;
    for (std::size_t i = 0; i < p.x.size() && i < p.y.size(); ++i)
      if (std::isfinite(p.x[i]) && std::isfinite(p.y[i]))
        pts += num(X(p.x[i])) + "," + num(Y(p.y[i], p.right_axis)) + " ";
    s += "<polyline fill=\"none\" stroke=\"" + p.color + "\" stroke-width=\"1.6\"" +
         (p.dashed ? " stroke-dasharray=\"6,4\"" : "") + " points=\"" + pts + "\"/>\n";
    s += "<line x1=\"" + num(L + 10) + "\" y1=\"" + num(ly) + "\" x2=\"" + num(L + 34) +
         "\" y2=\"" + num(ly) + "\" stroke=\"" + p.color + "\" stroke-width=\"2\"" +
         (p.dashed ? " stroke-dasharray=\"6,4\"" : "") + "/>\n";
    s += "<text x=\"" + num(L + 40) + "\" y=\"" + num(ly + 4) + "\">" + escape(p.label) +
         "</text>\n";
    ly += 16;
  }
  for (const PlotMarker& m : markers) {
    s += "<circle cx=\"" + num(X(m.x)) + "\" cy=\"" + num(Y(m.y, false)) +
         "\" r=\"4\" fill=\"none\" stroke=\"black\"/>\n";
    const bool right = X(m.x) > L + 0.85 * pw; // keep the label inside the picture
    s += "<text x=\"" + num(X(m.x) + (right ? -6 : 6)) + "\" y=\"" + num(Y(m.y, false) - 6) + "\"" +
         (right ? " text-anchor=\"end\"" : "") + ">" + escape(m.label) + "</text>\n";
  }
  s += "</svg>\n";
  return s;
}

std::string crack_map_svg(const Snapshot& snap, const std::string& title, int depth_axis) {
  // View: 2D as is (x right, y up). 3D: a thin section through the centre, seen along the depth
  // axis (y: x right, z up; z: x right, y up): the grains and cracks within 10 % of the
  // specimen's depth extent of the mid-plane, each crack drawn as its trace (a segment across the
  // projected normal; a circle when it lies in the section plane).
  const int dz = snap.dim == 2 ? 2 : depth_axis;
  const int vx = 0, vy = snap.dim == 2 ? 1 : (dz == 1 ? 2 : 1);
  double xlo = 1e300, xhi = -1e300, ylo = 1e300, yhi = -1e300, dlo = 1e300, dhi = -1e300;
  for (std::size_t i = 0; i < snap.pos.size(); ++i) {
    xlo = std::min(xlo, snap.pos[i][vx] - snap.radius[i]);
    xhi = std::max(xhi, snap.pos[i][vx] + snap.radius[i]);
    ylo = std::min(ylo, snap.pos[i][vy] - snap.radius[i]);
    yhi = std::max(yhi, snap.pos[i][vy] + snap.radius[i]);
    dlo = std::min(dlo, snap.pos[i][dz] - snap.radius[i]);
    dhi = std::max(dhi, snap.pos[i][dz] + snap.radius[i]);
  }
  if (xlo > xhi)
    xlo = 0, xhi = 1, ylo = 0, yhi = 1, dlo = dhi = 0;
  const double mid = 0.5 * (dlo + dhi), half = 0.1 * (dhi - dlo);
  auto in_section = [&](const Vec3& p) { return snap.dim == 2 || std::abs(p[dz] - mid) <= half; };
  const double margin = 20, top = 40, maxw = 640, maxh = 800;
  const double scale = std::min(maxw / (xhi - xlo), maxh / (yhi - ylo));
  const double W = (xhi - xlo) * scale + 2 * margin, H = (yhi - ylo) * scale + top + 2 * margin;
  auto X = [&](double v) { return margin + (v - xlo) * scale; };
  auto Y = [&](double v) { return top + margin + (yhi - v) * scale; };
  std::string s = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + num(W) + "\" height=\"" +
                  num(H + (snap.dim == 3 ? 16 : 0)) +
                  "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  s += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  s += "<text x=\"" + num(W / 2) + "\" y=\"20\" text-anchor=\"middle\" font-size=\"14\">" +
       escape(title) + "</text>\n";
  s += "<g fill=\"#e3e3e3\" stroke=\"#a0a0a0\" stroke-width=\"0.4\">\n";
  for (std::size_t i = 0; i < snap.pos.size(); ++i) {
    if (!in_section(snap.pos[i]))
      continue;
    // 3D: the grain's cut by the mid-plane (at least a third of its radius, to stay visible)
    double r = snap.radius[i];
    if (snap.dim == 3) {
      const double d = snap.pos[i][dz] - mid;
      r = std::sqrt(std::max(r * r - d * d, r * r / 9));
    }
    s += "<circle cx=\"" + num(X(snap.pos[i][vx])) + "\" cy=\"" + num(Y(snap.pos[i][vy])) +
         "\" r=\"" + num(r * scale) + "\"/>\n";
  }
  s += "</g>\n";
  std::size_t shown = 0;
  for (const CrackGlyph& c : snap.cracks) {
    if (!in_section(c.position))
      continue;
    ++shown;
    const char* color = c.mode == 1 ? "#d62728" : "#1f3fbf";
    const double r = 0.5 * c.size * scale;
    const double px = c.position[vx], py = c.position[vy];
    const double nx = c.normal[vx], ny = c.normal[vy];
    const double len = std::hypot(nx, ny);
    if (len < 0.2) { // (3D) a crack nearly in the section plane
      s += "<circle cx=\"" + num(X(px)) + "\" cy=\"" + num(Y(py)) + "\" r=\"" + num(r) +
           "\" fill=\"none\" stroke=\"" + color + "\" stroke-width=\"1\"/>\n";
      continue;
    }
    const double tx = -ny / len, ty = nx / len;
    s += "<line x1=\"" + num(X(px) - r * tx) + "\" y1=\"" + num(Y(py) + r * ty) + "\" x2=\"" +
         num(X(px) + r * tx) + "\" y2=\"" + num(Y(py) - r * ty) + "\" stroke=\"" + color +
         "\" stroke-width=\"1.5\"/>\n";
  }
  s += "<text x=\"" + num(margin) + "\" y=\"" + num(H - 6) +
       "\" fill=\"#d62728\">tension</text><text x=\"" + num(margin + 70) + "\" y=\"" + num(H - 6) +
       "\" fill=\"#1f3fbf\">shear</text>\n";
  if (snap.dim == 3)
    s += "<text x=\"" + num(margin) + "\" y=\"" + num(H + 10) + "\" fill=\"#555555\">section |" +
         std::string(1, "xyz"[dz]) + " - " + num(1e3 * mid) + " mm| &lt;= " + num(1e3 * half) +
         " mm: " + std::to_string(shown) + " of " + std::to_string(snap.cracks.size()) +
         " cracks</text>\n";
  s += "</svg>\n";
  return s;
}

} // namespace rocklab
