// The crack map (viz/svg_plots.hpp): the cracks of a snapshot over its grains, with the largest
// fracture events. Units SI in, millimetres in the caption.
#include "viz/svg_plots.hpp"
#include "viz/svg_text.hpp"

#include <algorithm>
#include <cmath>

namespace rocklab {

using svg::escape;
using svg::num;

namespace {

// The largest fracture events (at most 12, of 5 or more contacts), projected onto the picture: a
// ring whose area grows with the number of contacts, labelled with it. Returns how many.
template <class FX, class FY>
std::size_t draw_events(std::string& s, const Snapshot& snap, double scale, FX X, FY Y, int vx,
                        int vy) {
  double rmean = 0;
  for (double r : snap.radius)
    rmean += r / static_cast<double>(snap.radius.size());
  std::vector<const EventGlyph*> big;
  for (const EventGlyph& e : snap.events)
    if (e.contacts >= 5)
      big.push_back(&e);
  std::stable_sort(big.begin(), big.end(), [](const EventGlyph* a, const EventGlyph* b) {
    return a->contacts > b->contacts;
  });
  if (big.size() > 12)
    big.resize(12);
  for (const EventGlyph* e : big) {
    const double x = X(e->position[vx]), y = Y(e->position[vy]);
    const double r = 0.5 * rmean * scale * std::sqrt(e->contacts);
    s += "<circle class=\"event\" cx=\"" + num(x) + "\" cy=\"" + num(y) + "\" r=\"" + num(r) +
         "\" fill=\"none\" stroke=\"#ff8c00\" stroke-width=\"2.5\" stroke-opacity=\"0.9\"/>\n";
    s += "<text x=\"" + num(x + 0.72 * r) + "\" y=\"" + num(y - 0.72 * r) +
         "\" fill=\"#b35f00\" font-size=\"11\">" + std::to_string(e->contacts) + "</text>\n";
  }
  return big.size();
}

// A Brazilian disk's loaded diameter (dashed, at picture x `cx` from `top` to `bottom`) with the
// platens' contact points as arrow heads pointing at the disk.
void draw_loaded_diameter(std::string& s, double cx, double top, double bottom) {
  s += "<line x1=\"" + num(cx) + "\" y1=\"" + num(top) + "\" x2=\"" + num(cx) + "\" y2=\"" +
       num(bottom) + "\" stroke=\"#555555\" stroke-width=\"1\" stroke-dasharray=\"6,4\"/>\n";
  for (const double py : {top, bottom}) {
    const double dir = py == top ? -1 : 1;
    s += "<path d=\"M" + num(cx) + "," + num(py) + " l-7," + num(12 * dir) +
         " h14 z\" fill=\"#555555\"/>\n";
  }
  s += "<text x=\"" + num(cx + 6) + "\" y=\"" + num(0.5 * (top + bottom) - 4) +
       "\" fill=\"#555555\">loaded diameter</text>\n";
}

} // namespace

std::string crack_map_svg(const Snapshot& snap, const std::string& title, int depth_axis,
                          bool disk) {
  // View: 2D as is (x right, y up). 3D: the grains and cracks within 10 % of the depth extent of
  // the mid-plane, seen along the depth axis (y: x right, z up; z: x right, y up), each crack as
  // its trace (a segment across the projected normal; a circle when in the section plane).
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
  // A disk's cracks through its whole thickness (a thin section of a 12 mm disk showed 2 of its 21
  // broken contacts).
  auto crack_shown = [&](const Vec3& p) { return disk || in_section(p); };
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
  if (disk)
    draw_loaded_diameter(s, X(0.5 * (xlo + xhi)), Y(yhi), Y(ylo));
  const std::size_t events_shown = draw_events(s, snap, scale, X, Y, vx, vy);
  // One crack per broken contact when known (a flat joint's elements merged; its opacity grows
  // with the contact's damage), else every crack record.
  const bool per_contact = !snap.contact_cracks.empty();
  const std::vector<CrackGlyph>& cracks = per_contact ? snap.contact_cracks : snap.cracks;
  std::size_t shown = 0;
  for (const CrackGlyph& c : cracks) {
    if (!crack_shown(c.position))
      continue;
    ++shown;
    const char* color = c.mode == 1 ? "#d62728" : "#1f3fbf";
    const std::string opacity =
        per_contact
            ? " stroke-opacity=\"" + num(0.35 + 0.65 * std::clamp(c.damage, 0.0, 1.0)) + "\""
            : "";
    const double r = 0.5 * c.size * scale;
    const double px = c.position[vx], py = c.position[vy];
    const double nx = c.normal[vx], ny = c.normal[vy];
    const double len = std::hypot(nx, ny);
    if (len < 0.2) { // (3D) a crack nearly in the section plane
      s += "<circle cx=\"" + num(X(px)) + "\" cy=\"" + num(Y(py)) + "\" r=\"" + num(r) +
           "\" fill=\"none\" stroke=\"" + color + "\" stroke-width=\"1\"" + opacity + "/>\n";
      continue;
    }
    const double tx = -ny / len, ty = nx / len;
    s += "<line x1=\"" + num(X(px) - r * tx) + "\" y1=\"" + num(Y(py) + r * ty) + "\" x2=\"" +
         num(X(px) + r * tx) + "\" y2=\"" + num(Y(py) - r * ty) + "\" stroke=\"" + color +
         "\" stroke-width=\"1.5\"" + opacity + "/>\n";
  }
  s += "<text x=\"" + num(margin) + "\" y=\"" + num(H - 6) +
       "\" fill=\"#d62728\">tension</text><text x=\"" + num(margin + 70) + "\" y=\"" + num(H - 6) +
       "\" fill=\"#1f3fbf\">shear</text>";
  if (events_shown > 0)
    s += "<text x=\"" + num(margin + 130) + "\" y=\"" + num(H - 6) + "\" fill=\"#b35f00\">" +
         std::to_string(events_shown) + " largest events (contacts)</text>";
  s += "\n";
  const std::string what = per_contact ? " broken contacts" : " cracks";
  if (snap.dim == 3 && disk)
    s += "<text x=\"" + num(margin) + "\" y=\"" + num(H + 10) + "\" fill=\"#555555\">" +
         std::to_string(shown) + what +
         " through the disk's thickness, seen face-on; grains of "
         "its mid-section</text>\n";
  else if (snap.dim == 3)
    s += "<text x=\"" + num(margin) + "\" y=\"" + num(H + 10) + "\" fill=\"#555555\">" +
         std::to_string(shown) + " of " + std::to_string(cracks.size()) + what + " within " +
         num(1e3 * half) + " mm of " + std::string(1, "xyz"[dz]) + " = " + num(1e3 * mid) +
         " mm</text>\n";
  s += "</svg>\n";
  return s;
}

} // namespace rocklab
