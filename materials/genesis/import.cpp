// Genesis stage "import" (issue 15): the grains of another code's packing instead of a packed
// cloud, so a test runs on exactly the specimen that code uses. The card's `packing.import` names
// a text file with one grain per line, "x y z r" in 3D or "x y r" in 2D (metres; further columns,
// such as the clump id of YADE's SpherePack.save, are ignored; '#' starts a comment). The packing
// is moved so that its bounding box is centred on the origin, numbered along a Morton curve and
// handed to finalization (bonds where the gap is within the installation gap: the card's `gap`, or
// `gap_ratio` times the imported grains' mean radius) and release (relaxed to equilibrium; cut if
// the card asks). The specimen is the card's shape type at the packing's extent.
#include "core/spatial_order.hpp"
#include "io/input_error.hpp"
#include "materials/genesis/stages.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

namespace rocklab::genesis {

namespace {

struct Grain {
  Vec3 x = Vec3::Zero();
  double r = 0;
};

std::vector<Grain> read_packing_file(const std::string& file, int dim) {
  std::ifstream in(file);
  if (!in)
    throw InputError(file + ": cannot read the packing (key 'packing.import')");
  std::vector<Grain> grains;
  std::string line;
  for (std::int64_t no = 1; std::getline(in, line); ++no) {
    const std::string text = line.substr(0, line.find('#'));
    std::istringstream ss(text);
    double v[4];
    int n = 0;
    while (n < dim + 1 && ss >> v[n])
      ++n;
    if (n == 0 && text.find_first_not_of(" \t\r") == std::string::npos)
      continue; // blank or comment
    const std::string where = file + ": line " + std::to_string(no) + " ('" + line + "'): ";
    if (n < dim + 1)
      throw InputError(where + "expected " + std::string(dim == 3 ? "x y z r" : "x y r") +
                       " (metres) for a " + std::to_string(dim) + "D card");
    Grain g;
    for (int d = 0; d < dim; ++d)
      g.x[d] = v[d];
    g.r = v[dim];
    if (!(g.r > 0) || !std::isfinite(g.r) || !g.x.allFinite() || g.x.cwiseAbs().maxCoeff() > 1e6)
      throw InputError(where + "coordinates must be finite (|x| <= 1e6 m) and the radius in "
                               "(0, +inf) m");
    grains.push_back(g);
    if (grains.size() > 10'000'000)
      throw InputError(file + ": more than 10^7 grains (key 'packing.import')");
  }
  if (grains.size() < 2)
    throw InputError(file + ": a packing needs at least 2 grains, found " +
                     std::to_string(grains.size()) + " (key 'packing.import')");
  return grains;
}

// The card's shape type at the packing's extent (centred on the origin).
ShapeSpec extent_shape(const std::vector<Grain>& grains, SpecimenShape type, int dim) {
  ShapeSpec s;
  s.shape = type;
  Vec3 hi = Vec3::Zero();
  double radial = 0;
  for (const Grain& g : grains) {
    hi = hi.cwiseMax(g.x.cwiseAbs() + Vec3::Constant(g.r));
    radial = std::max(radial, std::hypot(g.x.x(), g.x.y()) + g.r);
  }
  switch (type) {
  case SpecimenShape::Cylinder:
    s.size = Vec3(2 * radial, 2 * hi.z(), 0);
    break;
  case SpecimenShape::Disk2D:
    s.size = Vec3(2 * radial, 0, 0);
    break;
  case SpecimenShape::Disk3D:
    s.size = Vec3(2 * radial, 2 * hi.z(), 0);
    break;
  default: // rectangle, prism
    s.size = 2 * hi;
    if (dim == 2)
      s.size.z() = 0;
  }
  return s;
}

} // namespace

void import_grains(Run& g) {
  Model& m = g.m;
  const MaterialCard& card = g.card;
  const int dim = card.dim;
  g.say("importing the packing");
  std::vector<Grain> grains = read_packing_file(card.packing_import, dim);
  Vec3 lo = Vec3::Constant(1e300), hi = -lo;
  double r_sum = 0;
  for (const Grain& q : grains) {
    lo = lo.cwiseMin(q.x - Vec3::Constant(q.r));
    hi = hi.cwiseMax(q.x + Vec3::Constant(q.r));
    r_sum += q.r;
  }
  const Vec3 centre = 0.5 * (lo + hi); // 2D: z stays 0 (-r_max and +r_max)
  std::vector<Vec3> x;
  for (Grain& q : grains) {
    q.x -= centre;
    x.push_back(q.x);
  }
  g.r_avg = r_sum / static_cast<double>(grains.size());
  if (card.install_gap_ratio >= 0)
    g.install_gap = card.install_gap_ratio * g.r_avg;
  const int group = m.group_index("grains");
  const std::vector<std::size_t> order = morton_order(x, dim, 2 * g.r_avg, -(hi - lo) / 2);
  g.radii.clear();
  for (std::size_t k = 0; k < order.size(); ++k) {
    const Grain& q = grains[order[k]];
    m.balls.add(dim, static_cast<std::int64_t>(k + 1), q.x, q.r, card.density, group);
    g.radii.push_back(q.r);
  }
  // Contacts at the card's grain stiffness; finalization gives those within g_i their bonds.
  ModelRule bb, bf;
  bb.props = card.linear;
  bf.ball_facet = true;
  bf.props = card.linear;
  m.rules = {bb, bf};
  m.settings.margin = std::max(0.05 * g.r_avg, g.install_gap * 1.01);
  m.initialize();
  GenesisReport& rep = g.rep;
  rep.shape = extent_shape(grains, card.vessel.shape, dim);
  g.installed_volume = rep.shape.volume(dim);
  rep.porosity_target = card.porosity;
  rep.porosity = rep.porosity_installed = rep.porosity_packed =
      1 - grain_volume_sum(m) / g.installed_volume;
  rep.pressure = 0;
  if (card.cut)
    rep.shape = *card.cut;
}

} // namespace rocklab::genesis
