// Non-affine strain of each grain (viz/nonaffine.hpp). Units SI.
#include "viz/nonaffine.hpp"

#include <Eigen/Dense>
#include <cmath>

namespace rocklab {

namespace {

// The least-squares F of one grain (normal equations: F = (sum x X^T)(sum X X^T)^-1) and its
// misfit ratio; dimension D.
template <int D>
double misfit(const std::vector<Vec3>& pos, const std::vector<Vec3>& disp,
              const std::vector<std::size_t>& nb, std::size_t i) {
  using V = Eigen::Matrix<double, D, 1>;
  using M = Eigen::Matrix<double, D, D>;
  if (nb.size() < static_cast<std::size_t>(D + 1))
    return 0.0;
  M xx = M::Zero(), dx = M::Zero();
  const Vec3 ref_i = pos[i] - disp[i];
  double branch2 = 0;
  for (const std::size_t j : nb) {
    const V X = (pos[j] - disp[j] - ref_i).head<D>();
    const V x = (pos[j] - pos[i]).head<D>();
    xx += X * X.transpose();
    dx += x * X.transpose();
    branch2 += X.squaredNorm();
  }
  const Eigen::FullPivLU<M> lu(xx);
  if (!lu.isInvertible() || branch2 <= 0)
    return 0.0; // the neighbours lie on a line (plane): no F to fit
  const M F = dx * lu.inverse();
  double misfit2 = 0;
  for (const std::size_t j : nb) {
    const V X = (pos[j] - disp[j] - ref_i).head<D>();
    const V x = (pos[j] - pos[i]).head<D>();
    misfit2 += (x - F * X).squaredNorm();
  }
  return std::sqrt(misfit2 / branch2);
}

} // namespace

std::vector<double> nonaffine_strain(const std::vector<Vec3>& pos, const std::vector<Vec3>& disp,
                                     const std::vector<std::vector<std::size_t>>& neighbours,
                                     int dim) {
  std::vector<double> out(pos.size(), 0.0);
  if (disp.size() != pos.size() || neighbours.size() != pos.size())
    return out;
#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i < pos.size(); ++i)
    out[i] =
        dim == 2 ? misfit<2>(pos, disp, neighbours[i], i) : misfit<3>(pos, disp, neighbours[i], i);
  return out;
}

} // namespace rocklab
