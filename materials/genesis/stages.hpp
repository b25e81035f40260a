// Material genesis stage by stage (docs/material-format.md, ../shared/DESIGN.md): the work in
// progress every stage reads and changes, and the stages run_genesis calls in order, one file
// each under materials/genesis/. Internal to materials/. Units SI.
#pragma once

#include "core/model.hpp"
#include "materials/genesis.hpp"

#include <atomic>
#include <cstdint>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace rocklab::genesis {

/// A uniform draw in [0, 1) from the run's own generator (portable across standard libraries).
double uniform01(std::mt19937_64& rng);
/// A draw from Normal(mean, sd), clamped at zero (Box-Muller on uniform01).
double normal(std::mt19937_64& rng, const Distribution& d);
double grain_volume(int dim, double r);
double grain_volume_sum(const Model& m);

/// A servo-controlled vessel wall.
struct Servo {
  std::size_t wall = 0;
  Vec3 n_in = Vec3::Zero(); ///< planar walls: inward normal
  bool radial = false;      ///< the round wall (cylinder or circle)
  template <class A> void fields(A& a) { a("wall", wall), a("n_in", n_in), a("radial", radial); }
};

/// The vessel of the card's specimen shape: planar walls and, for round shapes, a cylinder
/// (circle in 2D) wall, each servo-controlled (vessel.cpp).
struct Vessel {
  int dim = 3;
  SpecimenShape shape = SpecimenShape::Prism;
  std::vector<Servo> servos;

  double radius(const Model& m, const Servo& s) const { return m.walls[s.wall].cylinder_radius; }
  /// Current extent along `axis` between the two planar walls normal to it [m].
  double extent(const Model& m, int axis) const;
  double lateral_radius(const Model& m) const;
  double volume(const Model& m) const;
  /// The area a wall loads [m^2] (2D: per unit thickness).
  double area(const Model& m, const Servo& s) const;
  /// Distance of a wall from the vessel centre (its radius for the round wall) [m].
  double half_extent(const Model& m, const Servo& s) const;
  /// Compressive stress on a wall [Pa].
  double stress(const Model& m, const Servo& s) const;
  /// The vessel as a specimen shape (its size now).
  ShapeSpec shape_now(const Model& m) const;
  /// Whether point x lies inside every wall of the vessel (on the inner side of each plane, within
  /// the round wall's radius).
  bool holds(const Model& m, const Vec3& x) const;
};

/// Add the vessel of the card's specimen shape to the model, every length times `scale`.
Vessel make_vessel(Model& m, const MaterialCard& card, double scale);

/// One genesis run: the card, the model being made, its report and what the stages hand on.
struct Run {
  Run(const MaterialCard& c, Model& model, GenesisReport& r,
      const std::function<void(const std::string&)>& p, const std::atomic<bool>* i)
      : card(c), m(model), rep(r), progress(p), interrupt(i), rng(c.seed),
        install_gap(c.install_gap) {}

  const MaterialCard& card;
  Model& m;
  GenesisReport& rep;
  const std::function<void(const std::string&)>& progress;
  const std::atomic<bool>* interrupt;
  std::mt19937_64 rng;         ///< the card's seed; every random draw of genesis, in stage order
  std::vector<double> radii;   ///< grain radii at their final size, in ball order [m]
  double r_avg = 0;            ///< mean grain radius [m]
  bool contraction = true;     ///< packing by boundary contraction (else by grain scaling)
  double vessel_scale = 1;     ///< vessel size of the cloud / the card's
  double grain_scale = 1;      ///< grain size in the cloud / final
  Vessel vessel;               ///< the servo-controlled walls
  LinearProps stiff;           ///< the card's grain stiffness, installed once the porosity locks
  double speed_cap = 0.01;     ///< largest wall displacement per step / mean radius
  double largest_half = 0;     ///< largest wall distance from the centre when compaction began [m]
  double installed_volume = 0; ///< vessel volume at the end of installation [m^3]
  std::vector<double> k_sums;  ///< the servo's per-wall stiffness sums (reused)
  double install_gap;          ///< g_i [m]: the card's, or its ratio times an imported mean radius

  void say(const std::string& s) const {
    if (progress)
      progress(s);
  }
  void check_interrupt() const {
    if (interrupt && interrupt->load())
      throw std::runtime_error("interrupted");
  }
  /// Cycle in chunks of `check` until done(); a phase that does not finish within the card's
  /// max_cycles fails naming the key. Returns the cycles run.
  template <class Done> std::int64_t run_until(const char* phase, std::int64_t check, Done&& done) {
    const std::int64_t start = m.step();
    while (!done()) {
      if (m.step() - start > card.max_cycles)
        throw std::runtime_error(card.file + ": genesis phase '" + phase +
                                 "' did not converge in " + std::to_string(card.max_cycles) +
                                 " cycles (key 'packing.max_cycles')");
      m.cycle(check);
      m.clear_events();
      check_interrupt();
    }
    return m.step() - start;
  }
  /// One servo step of every vessel wall toward `target` [Pa]: the wall speed closes half the
  /// stress error per step, capped so the vessel contracts at one strain rate (the cap is
  /// proportional to the wall's distance from the centre).
  void servo_step(double target);
  bool stresses_within(double target, double tol) const;
  double porosity_now() const;
};

/// What a card's genesis will take (estimate.cpp); 0 for an imported packing.
struct GenesisEstimate {
  double grains = 0;  ///< expected grain count
  double bytes = 0;   ///< expected peak memory
  double seconds = 0; ///< expected wall time on one core at a preset's cycle count
};
/// The estimate, after refusing (InputError naming the key) a card that cannot finish: a specimen
/// narrower than two of its largest grains, more grains than memory holds, an installation gap
/// wider than a mean radius, an installation strain (pressure / grain modulus) outside
/// [1e-10, 0.05].
GenesisEstimate estimate_genesis(const MaterialCard& c);

// The stages, in order (the file that holds each).
void place_grains(Run& g); ///< cloud.cpp: radii, a cloud in the enlarged vessel, Morton order
/// import.cpp: instead of the three above, grains read from the card's `packing.import`
void import_grains(Run& g);
void relax_cloud(Run& g); ///< packing.cpp: soft packing springs, the cloud relaxed
/// packing.cpp: the detection margin while packing [m]: `packing.margin_ratio` R_avg, or by
/// default max(0.05 R_avg, g_i) (finalization raises it to 1.01 g_i in either case).
double packing_margin(const MaterialCard& card, double r_avg);
void compact(Run& g);         ///< compaction.cpp: to the porosity at the pressure, installed
void remove_floaters(Run& g); ///< floaters.cpp: count floaters, coordination; remove if asked
/// floaters.cpp: remove grains whose centre has left the vessel (after the cloud and compaction)
void remove_escaped(Run& g);
void join_clumps(Run& g);       ///< clumps.cpp: touching grains into rigid clumps (thesis App. B)
void finalize_contacts(Run& g); ///< finalization.cpp: bonds where the gap is within g_i
void release(Run& g);           ///< release.cpp: unload and remove the vessel, cut, relax
void insert_joints(Run& g);     ///< joints.cpp: contacts across joint planes become smooth joints

/// packing_cache.cpp: the compacted, installed packing kept in the folder ROCKLAB_PACKING_CACHE
/// names (off when unset or for an imported packing), keyed by every input read before
/// finalization and by the program's own bytes.
struct PackingKey {
  std::string file; ///< empty: no cache
  nlohmann::json inputs;
};
PackingKey packing_key(const Run& g); ///< after place_grains (the margin needs the mean radius)
/// Restore the model, the run's state and the report from the cache; false on a miss.
bool load_packing(Run& g, const PackingKey& key);
void store_packing(const Run& g, const PackingKey& key);

} // namespace rocklab::genesis
