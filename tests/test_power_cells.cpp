// Power (Laguerre) cells of a packing (viz/power_cells): a lattice's cells are its cubes; a random
// packing's clipped cells fill the specimen's shape (volumes sum to its volume), and every face
// between two grains is the same polygon seen from both, lying on their radical plane.
#include "helpers.hpp"
#include "viz/nonaffine.hpp"
#include "viz/power_cells.hpp"

#include <Eigen/Geometry>

#include <numbers>
#include <random>

namespace rocklab {
namespace {

TEST(PowerCells, ALatticeOfEqualSpheresHasCubicCells) {
  const double d = 2e-3;
  std::vector<Vec3> pos;
  std::vector<double> r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k)
        pos.emplace_back(i * d, j * d, k * d), r.push_back(0.5 * d);
  const ClipShape box = ClipShape::around(pos, r, 3, false);
  const auto cells = power_cells(pos, r, box);
  double sum = 0;
  for (const PowerCell& c : cells) {
    EXPECT_NEAR(c.volume, d * d * d, 1e-12 * d * d * d);
    sum += c.volume;
  }
  EXPECT_NEAR(sum, 27 * d * d * d, 1e-10 * d * d * d);
  // grain 0 (0,0,0) and grain 9 (d,0,0): a d x d square on x = d/2
  const auto* f = cells[0].face_with(9);
  ASSERT_NE(f, nullptr);
  EXPECT_NEAR(face_area(*f), d * d, 1e-12 * d * d);
  for (const Vec3& x : *f)
    EXPECT_NEAR(x.x(), 0.5 * d, 1e-15);
  EXPECT_EQ(cells[0].face_with(13),
            nullptr); // the centre grain is not a face neighbour of a corner
}

// A random polydisperse, partly overlapping packing in a cylinder (3D) or disk (2D).
void random_packing(int dim, std::vector<Vec3>& pos, std::vector<double>& r) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1), ur(0.6e-3, 1e-3);
  const double R = 8e-3, H = 16e-3;
  while (pos.size() < (dim == 3 ? 600u : 150u)) {
    const Vec3 x(R * u(rng), R * u(rng), dim == 3 ? 0.5 * H * u(rng) : 0);
    if (std::hypot(x.x(), x.y()) > R - 1e-3)
      continue;
    pos.push_back(x);
    r.push_back(ur(rng));
  }
}

TEST(PowerCells, ClippedCellsFillTheSpecimenAndShareTheirFaces) {
  for (int dim : {3, 2}) {
    std::vector<Vec3> pos;
    std::vector<double> r;
    random_packing(dim, pos, r);
    const ClipShape shape = ClipShape::around(pos, r, dim, true);
    const auto cells = power_cells(pos, r, shape);
    double sum = 0;
    std::size_t hidden = 0, boundary = 0;
    for (const PowerCell& c : cells) {
      sum += c.volume;
      hidden += c.faces.empty();
      for (auto n : c.neighbour)
        boundary += n < 0;
    }
    // The cells partition the clipped shape: the sum is its volume (the 96-gon prism), and that is
    // the round specimen's volume within 0.1 %.
    EXPECT_TRUE(test::near_rel(sum, shape.volume(), 1e-9)) << dim;
    const double round =
        dim == 3 ? std::numbers::pi * shape.radius * shape.radius * (shape.hi.z() - shape.lo.z())
                 : std::numbers::pi * shape.radius * shape.radius;
    EXPECT_TRUE(test::near_rel(sum, round, 1e-3)) << dim;
    EXPECT_GT(boundary, 0u);
    std::printf("%dD: %zu grains, %zu hidden, cell volumes sum %.9g, shape %.9g, round %.9g\n", dim,
                cells.size(), hidden, sum, shape.volume(), round);
    // Every face between grains i and j is the face of j with i: same area, on the radical plane.
    std::size_t faces = 0;
    for (std::size_t i = 0; i < cells.size(); ++i)
      for (std::size_t k = 0; k < cells[i].faces.size(); ++k) {
        const std::int64_t j = cells[i].neighbour[k];
        if (j < 0)
          continue;
        ++faces;
        const auto* other =
            cells[static_cast<std::size_t>(j)].face_with(static_cast<std::int64_t>(i));
        ASSERT_NE(other, nullptr) << i << " " << j;
        const double a = face_area(cells[i].faces[k]);
        EXPECT_NEAR(face_area(*other), a, 1e-9 * a + 1e-18) << i << " " << j;
        const auto ju = static_cast<std::size_t>(j);
        for (const Vec3& x : cells[i].faces[k]) {
          const double pi = (x - pos[i]).squaredNorm() - r[i] * r[i];
          const double pj = (x - pos[ju]).squaredNorm() - r[ju] * r[ju];
          EXPECT_NEAR(pi, pj, 1e-12);
        }
      }
    EXPECT_GT(faces, cells.size());
  }
}

// The non-affine strain (viz/nonaffine) over the power diagram's neighbours: zero for any affine
// motion (a finite rotation, stretch and shear plus a translation), and a slip across a plane is
// seen exactly by the grains with a neighbour across it and by no other.
TEST(NonaffineStrain, ZeroForAffineMotionAndOnlyBesideASlipPlane) {
  for (int dim : {3, 2}) {
    std::vector<Vec3> ref;
    std::vector<double> r;
    random_packing(dim, ref, r);
    const ClipShape shape = ClipShape::around(ref, r, dim, true);
    Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
    F(0, 0) = 1.004, F(1, 1) = 0.997, F(0, 1) = 0.002, F(2, 2) = dim == 3 ? 1.003 : 1.0;
    const Eigen::Matrix3d R = Eigen::AngleAxisd(0.5, Vec3::UnitZ()).toRotationMatrix();
    std::vector<Vec3> pos, disp;
    for (const Vec3& X : ref) {
      pos.push_back(R * F * X + Vec3(1e-3, -2e-3, 0));
      disp.push_back(pos.back() - X);
    }
    const PowerDiagram moved(pos, r, ClipShape::around(pos, r, dim, true));
    const auto affine = nonaffine_strain(pos, disp, moved.neighbours(), dim);
    for (const double e : affine)
      EXPECT_LT(e, 1e-12) << dim;

    // grains above y = 0 slide 40 um along x; the diagram of the reference packing
    const double slip = 40e-6;
    pos = ref;
    for (Vec3& x : pos)
      x.x() += x.y() > 0 ? slip : 0.0;
    for (std::size_t i = 0; i < pos.size(); ++i)
      disp[i] = pos[i] - ref[i];
    const PowerDiagram still(ref, r, shape);
    const auto strain = nonaffine_strain(pos, disp, still.neighbours(), dim);
    std::size_t beside = 0;
    double largest = 0;
    for (std::size_t i = 0; i < ref.size(); ++i) {
      bool across = false;
      for (const std::size_t j : still.neighbours()[i])
        across = across || (ref[j].y() > 0) != (ref[i].y() > 0);
      if (across) {
        ++beside;
        EXPECT_GT(strain[i], 1e-4) << dim << " grain " << i;
      } else {
        EXPECT_LT(strain[i], 1e-12) << dim << " grain " << i;
      }
      largest = std::max(largest, strain[i]);
    }
    // about one grain layer each side of the plane; the misfit is bounded by slip / branch length
    EXPECT_GT(beside, ref.size() / 20) << dim;
    EXPECT_LT(beside, ref.size() / 2) << dim;
    EXPECT_LT(largest, slip / 0.6e-3) << dim;
    std::printf("%dD: %zu of %zu grains beside the slip plane, largest non-affine strain %.4f\n",
                dim, beside, ref.size(), largest);
  }
}

} // namespace
} // namespace rocklab
