#include "core/servo.hpp"

#include "core/model.hpp"

namespace rocklab {

void wall_stiffness_sums(const Model& m, std::vector<double>& sums) {
  sums.assign(m.walls.size(), 0.0);
  const auto& cs = m.contacts();
  const auto& os = m.contact_outputs();
  for (std::size_t ci = 0; ci < cs.size(); ++ci)
    if (cs[ci].kind == ContactKind::BallFacet)
      sums[static_cast<std::size_t>(cs[ci].end2)] += os[ci].stiff.k_tran;
}

} // namespace rocklab
