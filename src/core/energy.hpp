// Energy ledger of the whole model. Stored partitions are current values; works and
// dissipations are accumulated since the start of the run. All in joules.
#pragma once

namespace rocklab {

struct EnergyLedger {
  double kinetic_translational = 0; ///< sum of m v^2 / 2 (half-step velocities)
  double kinetic_rotational = 0;    ///< sum of I w^2 / 2
  double strain = 0;                ///< stored in contact springs
  double bond_strain = 0;           ///< stored in bond springs
  double body_work = 0;             ///< work of gravity and applied loads (accumulated)
  double gravity_work = 0;          ///< the gravity part of body_work (accumulated)
  double boundary_work = 0;         ///< work of walls and DOF constraints (accumulated)
  double local_damping = 0;         ///< dissipated by local damping (accumulated)
  double slip = 0;                  ///< dissipated by frictional slip (accumulated)
  double dashpot = 0;               ///< dissipated by dashpots (accumulated)
  double plastic = 0;               ///< dissipated by plastic contact deformation (accumulated)
  /// Bond strain energy released when bonds break (accumulated): the energy each bond_break
  /// event reports. Exact for the parallel bond and tensile contact-bond breaks (all bond force
  /// vanishes); an upper bound where the broken contact keeps carrying compression.
  double bond_break = 0;
  double initial_total = 0; ///< kinetic + stored energy at initialization

  double kinetic() const { return kinetic_translational + kinetic_rotational; }
  double stored() const { return strain + bond_strain; }
  double dissipated() const { return local_damping + slip + dashpot + plastic + bond_break; }
  /// Energy in the system plus energy that left it, minus energy put in: zero when balanced.
  double balance_error() const {
    return kinetic() + stored() + dissipated() - (initial_total + body_work + boundary_work);
  }
  /// Every term, in one fixed order (specimen files, checkpoints, history rows).
  template <class F> void terms(F&& f) {
    f(kinetic_translational), f(kinetic_rotational), f(strain), f(bond_strain), f(body_work);
    f(gravity_work), f(boundary_work), f(local_damping), f(slip), f(dashpot), f(plastic);
    f(bond_break), f(initial_total);
  }
  static constexpr int kTerms = 13;
  /// The change of every term since `ref` (initial_total too, so the change balances on its
  /// own: its balance_error() is the error accrued since `ref`).
  EnergyLedger since(EnergyLedger ref) const {
    double r[kTerms];
    int i = 0;
    ref.terms([&](double& x) { r[i++] = x; });
    EnergyLedger d = *this;
    i = 0;
    d.terms([&](double& x) { x -= r[i++]; });
    return d;
  }
  /// Scale for a relative balance check.
  double balance_scale() const {
    return initial_total + (body_work < 0 ? -body_work : body_work) +
           (boundary_work < 0 ? -boundary_work : boundary_work) + kinetic() + stored() +
           dissipated();
  }
};

} // namespace rocklab
