// The DEM model: bodies, contacts, the cycle (time step, law of motion, detection,
// force-displacement), events and the energy ledger.
#pragma once

#include "contact/registry.hpp"
#include "core/balls.hpp"
#include "core/clumps.hpp"
#include "core/contact.hpp"
#include "core/energy.hpp"
#include "core/events.hpp"
#include "core/thread_plan.hpp"
#include "core/walls.hpp"

#include <array>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace rocklab {

namespace detail {
struct CellGrid;
}

/// A physical blow-up (NaN, overlap beyond a radius): the run cannot continue.
struct PhysicsError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct ModelSettings {
  int dim = 3;                  ///< 2 (unit-thickness disks in xy) or 3
  Vec3 gravity = Vec3::Zero();  ///< [m/s^2]
  double local_damping = 0.7;   ///< local damping factor alpha [-], [0, 1)
  double timestep = 0;          ///< > 0: fixed time step [s]; 0: automatic
  double timestep_safety = 0.8; ///< factor on the automatic estimate [-], (0, 1]
  double margin = 0;            ///< proximity margin [m]; 0: 0.1 x mean radius
  bool overlap_check = true;    ///< stop on an overlap beyond a radius (off for grain clouds)
  bool slip_events = true;      ///< record slip_change events (off where nobody reads them)
};

/// What Model::scale_density did.
struct DensityScaling {
  double quantile = 0;    ///< of the balls' own stable steps the step was raised to [-]
  double step_gain = 1;   ///< stiffness-limited time step after / before [-]
  std::size_t scaled = 0; ///< balls whose inertial mass or moment of inertia was raised
  double max_factor = 1;  ///< the largest factor on a mass or moment of inertia [-]
  template <class A> void fields(A& a) {
    a("quantile", quantile), a("step_gain", step_gain), a("scaled", scaled);
    a("max_factor", max_factor);
  }
};

/// Which contacts an operation applies to.
enum class ContactSelect { All, BallBall, BallFacet };

/// Which model a new contact gets. The first matching rule wins.
struct ModelRule {
  bool ball_facet = false; ///< false: ball-ball rule; true: ball-facet rule
  int group1 = -1;         ///< group of one ball (-1: any)
  int group2 = -1;         ///< group of the other ball (-1: any); unused for ball-facet
  int wall = -1;           ///< wall index for ball-facet rules (-1: any)
  bool inherit = false;    ///< ball-ball: inherit properties from the pieces' groups
  ModelProps props;
};

class Model {
public:
  ModelSettings settings;
  Balls balls;
  std::vector<Clump> clumps; ///< rigid bodies; their pebbles are balls with balls.clump >= 0
  std::vector<Wall> walls;
  std::vector<std::string> group_names;
  std::vector<ModelRule> rules;
  std::vector<SurfaceProps> surface; ///< per group index (may be shorter than group_names)

  /// Index of a group name, added if new.
  int group_index(const std::string& name);

  /// Add a clump of pebbles (global positions) at uniform density; mass, centroid and
  /// principal inertia from the pebble union (clumps.hpp). Pebbles get ids first_pebble_id,
  /// first_pebble_id + 1, ... and the clump's group. Returns the clump index. Call before
  /// initialize().
  std::size_t add_clump(const std::vector<Pebble>& pebbles, double density, int group,
                        std::int64_t id, std::int64_t first_pebble_id, const Vec3& velocity,
                        const Vec3& spin);
  /// Energy per group (index = group index), the thesis' sharing rule (section 3): a ball's or
  /// clump's kinetic energy and body work go to its group; a contact's stored and dissipated
  /// energies go fully to the group when both pieces are in it, half to each group otherwise
  /// (a wall belongs to no group: ball-facet contacts count fully to the ball's group).
  /// boundary_work and initial_total are model-wide and left at zero here. Summed over the
  /// groups, every other partition equals energy() to round-off.
  std::vector<EnergyLedger> group_energy() const;

  /// Detect contacts and compute the initial forces; call once after set-up.
  void initialize();
  /// Run n cycles.
  void cycle(std::int64_t n = 1);

  double time() const { return time_; }
  std::int64_t step() const { return step_; }
  double timestep() const { return dt_; } ///< the last cycle's time step [s] (0 before one)
  /// The time step the next cycle will take: the fixed one, or the automatic estimate [s].
  double estimate_timestep() const;
  double margin() const { return margin_; }
  const std::vector<Contact>& contacts() const { return contacts_; }
  /// Location, force, moment and stiffness of each contact (same index as contacts()).
  const std::vector<ContactOutput>& contact_outputs() const { return outputs_; }
  const ModelBatches& batches() const { return batches_; }

  /// Current energies (stored partitions summed over contacts, accumulated ones from the ledger).
  EnergyLedger energy() const;
  /// Mean unbalanced force over balls divided by the mean contact force magnitude. With moments
  /// (the scenes' stop rule): a ball's unbalanced moment over its radius counts as a force on its
  /// free rotations, and a contact's moment over its balls' mean radius adds to its load (as
  /// sqrt(F^2 + (M/R)^2)); clumps count their resultant force only.
  double mean_unbalanced_force_ratio(bool with_moments = false) const;
  /// Append the events buffered since the last drain (in a fixed order) to out and clear them.
  void drain_events(std::vector<Event>& out);
  /// Drop the buffered events (for callers that do not read them).
  void clear_events() { pending_events_.clear(); }
  /// Call a contact-model method on every contact of one model: "bond" / "unbond" (contact gap
  /// in [gap_lo, gap_hi]; flat joints: `element` 1..N or 0 for all) or "sj_setforce". With
  /// `gap_ratio` the bounds are fractions of each contact's R1 + R2 (ball-facet: its ball's R).
  /// Returns the number of contacts called.
  std::size_t apply_method(ModelKind kind, const std::string& method, double gap_lo, double gap_hi,
                           int element = 0, bool gap_ratio = false);
  /// Set a property of every existing contact of one model (like PFC's `contact property`):
  /// linear "fric", "kn" [N/m], "ks" [N/m]; linearpbond "fric" (its linear component);
  /// flatjoint "fj_fric"; smoothjoint "sj_fric". Returns the number of contacts changed; an
  /// unknown name throws std::invalid_argument. New contacts still follow the rules.
  std::size_t set_property(ModelKind kind, const std::string& name, double value,
                           ContactSelect which = ContactSelect::All);
  /// Change the proximity margin and re-detect (e.g. to reach an installation gap) [m].
  void set_margin(double margin);
  /// Remove the walls flagged in `remove` and their contacts.
  void remove_walls(const std::vector<bool>& remove);
  /// Give contact `ci` a new model (material finalization, joint insertion).
  void replace_contact_model(std::size_t ci, const ModelProps& props);
  /// Renumber the balls before initialize(): order[k] is the index of the ball that goes to place
  /// k (every per-ball array and the clumps' pebbles follow; ids stay). Throws std::logic_error
  /// once the model is initialized.
  void renumber_balls(const std::vector<std::size_t>& order);
  /// Renumber the balls along a Morton curve (spatial_order.hpp) before initialize() when their
  /// order is poor: at least kRenumberMin balls whose consecutive centres lie on average more
  /// than kOrderedStep mean radii apart (a packing sorted by size, or shuffled). Then the cycle's
  /// threads share few grains (ThreadPlan). Returns whether it renumbered; ids stay.
  bool renumber_spatially();
  static constexpr std::size_t kRenumberMin = 1024;
  /// The fraction of the cycle's work each OpenMP thread starts with (normalized; by default
  /// equal). The shares then follow the threads' measured speed; results never depend on them.
  void set_thread_shares(const std::vector<double>& shares);
  static constexpr double kOrderedStep = 8.0;
  /// Remove the balls flagged in `remove` and their contacts (cutting a specimen, floaters).
  void remove_balls(const std::vector<bool>& remove);
  /// Average stress tensor of the balls in `volume` [m^3] (2D: area x unit thickness) from the
  /// contact forces (Love's formula), tension positive [Pa].
  Eigen::Matrix3d average_stress(double volume) const;
  /// Number of contacts whose model reports them active (carrying load).
  std::size_t active_contact_count() const;
  /// Density scaling for quasi-static runs (src/core/density_scaling.cpp): every free ball whose
  /// own stable step (sqrt(m / k_tran), sqrt(I / k_rot) with its contacts' stiffness now) is below
  /// the `quantile` of all free balls' steps gets the inertial mass and moment of inertia that
  /// give it that step, so the automatic time step rises to that quantile. Gravity and outputs
  /// keep the true masses; each ball keeps its kinetic energy (its velocity is scaled), so the
  /// energy ledger stays closed. quantile 0 (or a change in the number of balls) turns it off.
  DensityScaling scale_density(double quantile);
  bool density_scaled() const { return !mass_scale_.empty() && mass_scale_.size() == balls.size(); }
  /// The mass and moment of inertia the law of motion uses (the true ones without scaling).
  double inertial_mass(std::size_t i) const {
    return density_scaled() ? balls.mass[i] * mass_scale_[i] : balls.mass[i];
  }
  double inertial_inertia(std::size_t i) const {
    return density_scaled() ? balls.inertia[i] * inertia_scale_[i] : balls.inertia[i];
  }

  /// Free the scratch arrays of contact detection (candidate keys, a byte per contact of the
  /// rebuild plan, the contacts a detection adds); the next detection allocates them again. For
  /// the end of a run, when outputs are written.
  void release_scratch();

  /// Read or write the whole state (archive = specimen/checkpoint reader or writer).
  template <class Archive> void serialize(Archive& a);
  /// After reading: every index in range and every value a run can use, else the corrupt part
  /// (a specimen or checkpoint file's body is validated field by field, src/io/specimen.cpp).
  std::string check_loaded() const;

private:
  void ensure_thread_buffers();
  void rebuild_adjacency();
  /// Bring plan_ up to date with the balls, contacts and thread count (thread_plan.cpp).
  const detail::ThreadPlan& plan_threads();
  /// Book the time range t of the contact loop took; after some steps, move the shares towards
  /// the threads' measured speeds (thread_plan.cpp).
  void time_range(std::size_t t, double seconds);
  void balance_threads();
  void retire_dissipation(const Contact& c);
  void move_clumps(double dt, std::array<double, 4>& sums);
  /// Add `share` of a contact's energies to the group ledgers (sharing rule).
  void share_contact_energy(const Contact& c, const ContactEnergy& e,
                            std::vector<EnergyLedger>& out) const;
  // contact_list.cpp
  void compact_contacts(const std::function<bool(Contact&)>& keep);
  void rebuild_contacts();
  bool batches_packed() const;
  void pack_batches();
  // detection.cpp
  void detect();
  detail::CellGrid bin_balls();
  void gather_candidates(const detail::CellGrid& grid);
  void merge_candidates();
  void retire_contact(std::size_t ci);
  void create_contact(std::uint64_t key);
  // forces.cpp
  void force_displacement(double dt_increment);
  bool update_contact_force(std::size_t ci, double dt, EventBuffer& events);
  void book_events(std::size_t first);
  double sum_ball_forces();
  void sum_wall_forces();
  [[noreturn]] void throw_overlap_blowup(std::size_t ci) const;
  // motion.cpp
  void law_of_motion(double dt);
  void track_motion(double dt);
  /// The largest speed of any ball surface point (centre speed + radius x spin) [m/s].
  double fastest_point_speed() const;
  bool needs_detection() const;

  std::vector<Contact> contacts_;
  std::vector<ContactOutput> outputs_;
  ModelBatches batches_;
  // Scratch storage reused between detections (no allocation in the steady cycle): the contacts
  // a detection adds and the plan of the rebuilt list (contact_list.cpp).
  std::vector<Contact> added_contacts_;
  std::vector<ContactOutput> added_outputs_;
  ModelBatches added_batches_;
  std::vector<std::uint8_t> keep_, order_;
  std::vector<std::uint64_t> candidate_keys_;
  std::vector<std::vector<std::uint64_t>> thread_keys_;
  std::vector<std::int32_t> cell_start_, cell_items_;
  std::vector<std::int32_t> adj_start_, adj_items_; // ball -> contacts (index*2 + side)
  std::vector<std::int32_t> adj_cursor_;
  std::vector<std::int32_t> facet_contacts_; ///< ball-facet contacts in contact order (walls' sums)
  std::uint64_t adjacency_generation_ = 0;   ///< counts rebuild_adjacency calls
  detail::ThreadPlan plan_;
  std::vector<std::array<double, 4>> motion_parts_; ///< per-block sums of the law of motion
  /// What one ball's step adds to the ledger (motion.cpp), kept where two threads share a block.
  struct BallWork {
    std::array<double, 6> constraint{}; ///< work of each fixed DOF's constraint [J]
    double body = 0, gravity = 0, damping = 0;
  };
  std::vector<BallWork> motion_spill_;             ///< the shared blocks' per-ball records
  std::vector<std::array<double, 4>> range_parts_; ///< per-thread-range results of a loop
  std::vector<EventBuffer> thread_events_;
  std::vector<Event> pending_events_;

  double time_ = 0;
  double dt_ = 0;
  double margin_ = 0;
  double max_ball_disp_ = 0;
  double wall_disp_ = 0;
  double max_speed_ = 0;
  double dt_stiffness_ = 0; ///< stiffness-limited step from the last force update [s]
  std::int64_t step_ = 0;
  bool initialized_ = false;
  EnergyLedger ledger_;
  ContactEnergy retired_; ///< dissipation of deleted contacts
  /// Per group: dissipation of deleted contacts and work of removed balls (group tracing).
  std::vector<EnergyLedger> group_retired_;
  /// Per group: bond energy released by breaks (in the bond_strain field, see group_energy).
  std::vector<EnergyLedger> broken_;
  std::size_t blowup_contact_ = 0;
  /// Density scaling: factors (>= 1) on each ball's mass and moment of inertia; empty when off.
  std::vector<double> mass_scale_, inertia_scale_;
};

} // namespace rocklab
