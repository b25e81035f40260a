// The energy ledger: stored energies summed over contacts, dissipation of deleted contacts kept,
// and per-group tracing with the rock-impact thesis' sharing rule (section 3).
#include "core/model.hpp"

#include "core/parallel.hpp"

#include <algorithm>

namespace rocklab {

using namespace detail;

void Model::retire_dissipation(const Contact& c) {
  // Dissipation so far stays in the ledger; stored energy leaves with the contact.
  ContactEnergy e = contact_energy(batches_, c.model, c.slot);
  e.strain = e.bond_strain = 0;
  retired_ += e;
  share_contact_energy(c, e, group_retired_);
}

void Model::share_contact_energy(const Contact& c, const ContactEnergy& e,
                                 std::vector<EnergyLedger>& out) const {
  // Thesis section 3: a contact inside one group counts fully to it, a contact between two
  // groups half to each; a wall is in no group.
  auto add = [&](std::int32_t g, double f) {
    const std::size_t k = static_cast<std::size_t>(g);
    if (out.size() <= k)
      out.resize(k + 1);
    EnergyLedger& l = out[k];
    l.strain += f * e.strain;
    l.bond_strain += f * e.bond_strain;
    l.slip += f * e.slip;
    l.dashpot += f * e.dashpot;
    l.plastic += f * e.plastic;
  };
  const std::int32_t g1 = balls.group[static_cast<std::size_t>(c.end1)];
  if (c.kind == ContactKind::BallFacet) {
    add(g1, 1.0);
    return;
  }
  const std::int32_t g2 = balls.group[static_cast<std::size_t>(c.end2)];
  if (g1 == g2) {
    add(g1, 1.0);
  } else {
    add(g1, 0.5);
    add(g2, 0.5);
  }
}

std::vector<EnergyLedger> Model::group_energy() const {
  std::vector<EnergyLedger> out = group_retired_;
  out.resize(std::max({out.size(), group_names.size(), broken_.size()}));
  for (std::size_t g = 0; g < broken_.size(); ++g)
    out[g].bond_break += broken_[g].bond_strain; // released bond energy (kept in bond_strain)
  auto at = [&](std::int32_t g) -> EnergyLedger& {
    const std::size_t k = static_cast<std::size_t>(g);
    if (out.size() <= k)
      out.resize(k + 1);
    return out[k];
  };
  for (std::size_t i = 0; i < balls.size(); ++i) {
    if (balls.clump[i] >= 0)
      continue;
    EnergyLedger& l = at(balls.group[i]);
    l.kinetic_translational += 0.5 * inertial_mass(i) * balls.vel[i].squaredNorm(); // Eq. 4
    l.kinetic_rotational += 0.5 * inertial_inertia(i) * balls.spin[i].squaredNorm();
    l.body_work += balls.body_work[i];
    l.gravity_work += balls.gravity_work[i];
    l.local_damping += balls.damping_work[i];
  }
  for (const Clump& c : clumps) {
    EnergyLedger& l = at(c.group);
    l.kinetic_translational += c.kinetic_translational();
    l.kinetic_rotational += c.kinetic_rotational();
    l.body_work += c.body_work;
    l.gravity_work += c.gravity_work;
    l.local_damping += c.local_damping;
  }
  for (const Contact& c : contacts_)
    share_contact_energy(c, contact_energy(batches_, c.model, c.slot), out); // Eq. 5-6, 10
  return out;
}

EnergyLedger Model::energy() const {
  EnergyLedger e = ledger_;
  const auto kin = block_sum<2>(balls.size(), [&](std::size_t i, std::array<double, 2>& acc) {
    if (balls.clump[i] >= 0)
      return; // counted with the clump
    acc[0] += 0.5 * inertial_mass(i) * balls.vel[i].squaredNorm();
    acc[1] += 0.5 * inertial_inertia(i) * balls.spin[i].squaredNorm();
  });
  e.kinetic_translational = kin[0];
  e.kinetic_rotational = kin[1];
  for (const Clump& c : clumps) {
    e.kinetic_translational += c.kinetic_translational();
    e.kinetic_rotational += c.kinetic_rotational();
  }
  const auto con = block_sum<5>(contacts_.size(), [&](std::size_t ci, std::array<double, 5>& acc) {
    const Contact& c = contacts_[ci];
    const ContactEnergy ce = contact_energy(batches_, c.model, c.slot);
    acc[0] += ce.strain;
    acc[1] += ce.bond_strain;
    acc[2] += ce.slip;
    acc[3] += ce.dashpot;
    acc[4] += ce.plastic;
  });
  e.strain = con[0];
  e.bond_strain = con[1];
  e.slip = con[2] + retired_.slip;
  e.dashpot = con[3] + retired_.dashpot;
  e.plastic = con[4] + retired_.plastic;
  return e;
}

} // namespace rocklab
