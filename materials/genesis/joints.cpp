// Genesis stage "joint sets": contacts straddling a joint plane (or one of a set of parallel
// planes) become smooth joints with the joint's properties.
#include "materials/genesis/stages.hpp"

namespace rocklab::genesis {

void insert_joints(Run& g) {
  Model& m = g.m;
  const MaterialCard& card = g.card;
  const int dim = card.dim;
  // Joint sets: contacts straddling a joint plane become smooth joints.
  for (const JointSpec& j : card.joints) {
    const Vec3 n = smoothjoint::joint_normal(dim, j.dip, j.ddir);
    const double extent = card.vessel.size.maxCoeff();
    std::vector<double> offsets{0};
    if (j.spacing > 0)
      for (double o = j.spacing; o < extent; o += j.spacing) {
        offsets.push_back(o);
        offsets.push_back(-o);
      }
    for (std::size_t ci = 0; ci < m.contacts().size(); ++ci) {
      const Contact& c = m.contacts()[ci];
      if (c.kind != ContactKind::BallBall || c.model == model_kind<SmoothJoint>)
        continue;
      const Vec3& a = m.balls.pos[static_cast<std::size_t>(c.end1)];
      const Vec3& b = m.balls.pos[static_cast<std::size_t>(c.end2)];
      for (double o : offsets) {
        const double da = (a - j.point).dot(n) - o, db = (b - j.point).dot(n) - o;
        if ((da < 0) != (db < 0)) {
          m.replace_contact_model(ci, j.props);
          break;
        }
      }
    }
  }
}

} // namespace rocklab::genesis
