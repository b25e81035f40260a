// Registry of contact models: one enum value, one batch, one props alternative per model, and
// one case in each dispatch function below. The engine calls only these functions.
#pragma once

#include "contact/flat_joint.hpp"
#include "contact/impact_models.hpp"
#include "contact/linear.hpp"
#include "contact/parallel_bond.hpp"
#include "contact/smooth_joint.hpp"

#include <cmath>
#include <limits>
#include <span>
#include <string_view>
#include <variant>
#include <vector>

namespace rocklab {

enum class ModelKind : std::uint8_t {
  Linear,
  PBond,
  FlatJoint,
  SmoothJoint,
  Hysteresis,
  PowerPlastic,
  ContactBond
};

inline constexpr std::string_view model_name(ModelKind k) {
  switch (k) {
  case ModelKind::Linear:
    return "linear";
  case ModelKind::PBond:
    return "linearpbond";
  case ModelKind::FlatJoint:
    return "flatjoint";
  case ModelKind::SmoothJoint:
    return "smoothjoint";
  case ModelKind::Hysteresis:
    return "hysteretic";
  case ModelKind::PowerPlastic:
    return "powerplastic";
  case ModelKind::ContactBond:
    return "contactbond";
  }
  return "unknown";
}

/// Per-model contiguous storage of contact data (parameters + state).
struct ModelBatches {
  std::vector<LinearContact> linear;
  std::vector<PBondContact> pbond;
  std::vector<FlatJointContact> flatjoint;
  std::vector<FlatJointElement> fj_elements; ///< elements of all flat joints, contact by contact
  std::vector<SmoothJointContact> smoothjoint;
  std::vector<HysteresisContact> hysteresis;
  std::vector<PowerPlasticContact> powerplastic;
  std::vector<ContactBondContact> contactbond;

  void clear() {
    linear.clear();
    pbond.clear();
    flatjoint.clear();
    fj_elements.clear();
    smoothjoint.clear();
    hysteresis.clear();
    powerplastic.clear();
    contactbond.clear();
  }
  std::span<FlatJointElement> elements(const FlatJointContact& c) {
    return {fj_elements.data() + c.elem, c.n_elem};
  }
  std::span<const FlatJointElement> elements(const FlatJointContact& c) const {
    return {fj_elements.data() + c.elem, c.n_elem};
  }
};

/// Properties a scene assigns to a class of contacts; the alternative selects the model
/// (same order as ModelKind).
using ModelProps = std::variant<LinearProps, PBondProps, FlatJointProps, SmoothJointProps,
                                HysteresisProps, PowerPlasticProps, ContactBondProps>;

inline ModelKind kind_of(const ModelProps& p) {
  return static_cast<ModelKind>(p.index());
}

/// Surface properties of the pieces of one group, inherited by contacts whose rule asks for it.
/// NaN: the group does not hold the property.
struct SurfaceProps {
  double kn = std::numeric_limits<double>::quiet_NaN();      ///< [N/m]
  double ks = std::numeric_limits<double>::quiet_NaN();      ///< [N/m]
  double fric = std::numeric_limits<double>::quiet_NaN();    ///< [-]
  double sj_kn = std::numeric_limits<double>::quiet_NaN();   ///< [Pa/m]
  double sj_ks = std::numeric_limits<double>::quiet_NaN();   ///< [Pa/m]
  double sj_fric = std::numeric_limits<double>::quiet_NaN(); ///< [-]
};

/// Property inheritance: stiffnesses of the two pieces act in series and the friction is the
/// smaller one (smooth-joint Eq. 18-19; the linear stiffnesses and friction inherit the same
/// way). A property is inherited only when both pieces hold it.
inline void inherit_properties(ModelProps& props, const SurfaceProps& a, const SurfaceProps& b) {
  auto series = [](double& k, double k1, double k2) {
    if (!std::isnan(k1) && !std::isnan(k2))
      k = (k1 > 0 && k2 > 0) ? 1.0 / (1.0 / k1 + 1.0 / k2) : 0.0; // Eq. 18
  };
  auto minimum = [](double& mu, double m1, double m2) {
    if (!std::isnan(m1) && !std::isnan(m2))
      mu = std::min(m1, m2); // Eq. 19
  };
  auto linear_part = [&](LinearProps& p) {
    if (p.emod <= 0) {
      series(p.kn, a.kn, b.kn);
      series(p.ks, a.ks, b.ks);
    }
    minimum(p.fric, a.fric, b.fric);
  };
  if (auto* l = std::get_if<LinearProps>(&props))
    linear_part(*l);
  else if (auto* pb = std::get_if<PBondProps>(&props))
    linear_part(pb->linear);
  else if (auto* cb = std::get_if<ContactBondProps>(&props))
    linear_part(cb->linear);
  else if (auto* sj = std::get_if<SmoothJointProps>(&props)) {
    series(sj->sj_kn, a.sj_kn, b.sj_kn);
    series(sj->sj_ks, a.sj_ks, b.sj_ks);
    minimum(sj->sj_fric, a.sj_fric, b.sj_fric);
  }
}

/// Geometry a model may need when it is created.
struct CreationInfo {
  int dim = 3;
  double R1 = 0, R2 = 0; ///< piece radii (R2 = 0 for a facet)
  bool ball_facet = false;
  double gap = 0;         ///< contact gap at creation [m]
  Vec3 n = Vec3::UnitX(); ///< contact normal at creation
};

inline std::uint32_t create_contact_data(ModelBatches& b, const ModelProps& props,
                                         const CreationInfo& ci) {
  switch (kind_of(props)) {
  case ModelKind::Linear:
    b.linear.push_back(LinearContact{
        linear::make_params(std::get<LinearProps>(props), ci.dim, ci.R1, ci.R2, ci.ball_facet),
        {}});
    return static_cast<std::uint32_t>(b.linear.size() - 1);
  case ModelKind::PBond:
    b.pbond.push_back(
        pbond::make(std::get<PBondProps>(props), ci.dim, ci.R1, ci.R2, ci.ball_facet, ci.gap));
    return static_cast<std::uint32_t>(b.pbond.size() - 1);
  case ModelKind::FlatJoint:
    b.flatjoint.push_back(flatjoint::make(std::get<FlatJointProps>(props), ci.dim, ci.R1, ci.R2,
                                          ci.ball_facet, b.fj_elements));
    return static_cast<std::uint32_t>(b.flatjoint.size() - 1);
  case ModelKind::SmoothJoint:
    b.smoothjoint.push_back(
        smoothjoint::make(std::get<SmoothJointProps>(props), ci.dim, ci.R1, ci.R2, ci.n, ci.gap));
    return static_cast<std::uint32_t>(b.smoothjoint.size() - 1);
  case ModelKind::Hysteresis:
    b.hysteresis.push_back(hysteresis::make(std::get<HysteresisProps>(props)));
    return static_cast<std::uint32_t>(b.hysteresis.size() - 1);
  case ModelKind::PowerPlastic:
    b.powerplastic.push_back(powerplastic::make(std::get<PowerPlasticProps>(props)));
    return static_cast<std::uint32_t>(b.powerplastic.size() - 1);
  case ModelKind::ContactBond:
    b.contactbond.push_back(contactbond::make(std::get<ContactBondProps>(props), ci.dim, ci.R1,
                                              ci.R2, ci.ball_facet, ci.gap));
    return static_cast<std::uint32_t>(b.contactbond.size() - 1);
  }
  __builtin_unreachable();
}

/// Move the data of one contact into another batch set (used when the list is rebuilt).
inline std::uint32_t move_contact_data(ModelBatches& to, const ModelBatches& from, ModelKind kind,
                                       std::uint32_t slot) {
  switch (kind) {
  case ModelKind::Linear:
    to.linear.push_back(from.linear[slot]);
    return static_cast<std::uint32_t>(to.linear.size() - 1);
  case ModelKind::PBond:
    to.pbond.push_back(from.pbond[slot]);
    return static_cast<std::uint32_t>(to.pbond.size() - 1);
  case ModelKind::FlatJoint: {
    FlatJointContact c = from.flatjoint[slot];
    const auto e = from.elements(c);
    c.elem = static_cast<std::uint32_t>(to.fj_elements.size());
    to.fj_elements.insert(to.fj_elements.end(), e.begin(), e.end());
    to.flatjoint.push_back(c);
    return static_cast<std::uint32_t>(to.flatjoint.size() - 1);
  }
  case ModelKind::SmoothJoint:
    to.smoothjoint.push_back(from.smoothjoint[slot]);
    return static_cast<std::uint32_t>(to.smoothjoint.size() - 1);
  case ModelKind::Hysteresis:
    to.hysteresis.push_back(from.hysteresis[slot]);
    return static_cast<std::uint32_t>(to.hysteresis.size() - 1);
  case ModelKind::PowerPlastic:
    to.powerplastic.push_back(from.powerplastic[slot]);
    return static_cast<std::uint32_t>(to.powerplastic.size() - 1);
  case ModelKind::ContactBond:
    to.contactbond.push_back(from.contactbond[slot]);
    return static_cast<std::uint32_t>(to.contactbond.size() - 1);
  }
  __builtin_unreachable();
}

/// Force-displacement update of one contact; out is in contact-plane coordinates.
inline void update_contact(ModelBatches& b, ModelKind kind, std::uint32_t slot,
                           const ContactKinematics& k, ContactResult& out, EventSink& ev) noexcept {
  switch (kind) {
  case ModelKind::Linear:
    linear::update(b.linear[slot], k, out, ev);
    return;
  case ModelKind::PBond:
    pbond::update(b.pbond[slot], k, out, ev);
    return;
  case ModelKind::FlatJoint: {
    FlatJointContact& c = b.flatjoint[slot];
    flatjoint::update(c, b.elements(c), k, out, ev);
    return;
  }
  case ModelKind::SmoothJoint: {
    // The smooth joint works on the joint plane: give it the global increment, take back the
    // global force in contact-plane components.
    const Vec3 d = k.d_dn * k.n + k.d_dss * k.s + k.d_dst * k.t;
    Vec3 F;
    smoothjoint::update(b.smoothjoint[slot], d, k.gap, F, ev);
    out = ContactResult{-F.dot(k.n), F.dot(k.s), F.dot(k.t), 0, 0, 0};
    return;
  }
  case ModelKind::Hysteresis:
    hysteresis::update(b.hysteresis[slot], k, out, ev);
    return;
  case ModelKind::PowerPlastic:
    powerplastic::update(b.powerplastic[slot], k, out, ev);
    return;
  case ModelKind::ContactBond:
    contactbond::update(b.contactbond[slot], k, out, ev);
    return;
  }
}

inline ContactStiffness contact_stiffness(const ModelBatches& b, ModelKind kind,
                                          std::uint32_t slot) {
  switch (kind) {
  case ModelKind::Linear:
    return linear::stiffness(b.linear[slot]);
  case ModelKind::PBond:
    return pbond::stiffness(b.pbond[slot]);
  case ModelKind::FlatJoint:
    return flatjoint::stiffness(b.flatjoint[slot]);
  case ModelKind::SmoothJoint:
    return smoothjoint::stiffness(b.smoothjoint[slot]);
  case ModelKind::Hysteresis:
    return hysteresis::stiffness(b.hysteresis[slot]);
  case ModelKind::PowerPlastic:
    return powerplastic::stiffness(b.powerplastic[slot]);
  case ModelKind::ContactBond:
    return contactbond::stiffness(b.contactbond[slot]);
  }
  __builtin_unreachable();
}

inline ContactEnergy contact_energy(const ModelBatches& b, ModelKind kind, std::uint32_t slot) {
  switch (kind) {
  case ModelKind::Linear:
    return linear::energy(b.linear[slot]);
  case ModelKind::PBond:
    return pbond::energy(b.pbond[slot]);
  case ModelKind::FlatJoint:
    return flatjoint::energy(b.flatjoint[slot], b.elements(b.flatjoint[slot]));
  case ModelKind::SmoothJoint:
    return smoothjoint::energy(b.smoothjoint[slot]);
  case ModelKind::Hysteresis:
    return hysteresis::energy(b.hysteresis[slot]);
  case ModelKind::PowerPlastic:
    return powerplastic::energy(b.powerplastic[slot]);
  case ModelKind::ContactBond:
    return contactbond::energy(b.contactbond[slot]);
  }
  __builtin_unreachable();
}

inline bool contact_keeps_alive(const ModelBatches& b, ModelKind kind, std::uint32_t slot) {
  switch (kind) {
  case ModelKind::Linear:
    return linear::keeps_alive(b.linear[slot]);
  case ModelKind::PBond:
    return pbond::keeps_alive(b.pbond[slot]);
  case ModelKind::FlatJoint:
    return flatjoint::keeps_alive(b.flatjoint[slot], b.elements(b.flatjoint[slot]));
  case ModelKind::SmoothJoint:
    return smoothjoint::keeps_alive(b.smoothjoint[slot]);
  case ModelKind::Hysteresis:
    return hysteresis::keeps_alive(b.hysteresis[slot]);
  case ModelKind::PowerPlastic:
    return powerplastic::keeps_alive(b.powerplastic[slot]);
  case ModelKind::ContactBond:
    return contactbond::keeps_alive(b.contactbond[slot]);
  }
  __builtin_unreachable();
}

} // namespace rocklab
