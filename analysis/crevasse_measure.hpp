#pragma once
// Crevasse positions, depths and spacings from a particle snapshot.
// Definitions and the reasons for each default: docs/measurement.md.
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "engine/groups.hpp"
#include "analysis/surface_profile.hpp"
#include "engine/snapshot.hpp"

namespace crevasse::analysis {

// Every length default is a multiple of dx, H_i or the particle spacing, so that a setting means
// the same thing at every resolution and thickness. Optional fields override the snapshot.
struct MeasureSettings {
  // Damaged ⇔ 1 − exp(−ζ ε_v^p) ≥ damage_threshold (docs/measurement.md); tied to strength loss, so it
  // stays consistent when ζ is scaled with dx.
  double damage_threshold = 0.95;
  // Used instead when the snapshot has no softening (ζ = 0): damaged ⇔ ε_v^p ≥ this.
  double eps_v_p_threshold = 0.01;

  // Which particle field is measured (docs/measurement.md, "Gate frame"):
  //   "gate":  the damage each particle carried when it reached the top of the step, drawn at
  //            its initial position — the fracture pattern the ice took over the step, before
  //            falling blocks shatter on the floor. Needs a snapshot with gate records.
  //   "final": the particles where they are at the snapshot's time.
  //   "passed": the particles where they are at the snapshot's time, in the ice that came over
  //            the step during the run: window [step_top_x + margin·H_i, front of the ice that
  //            started upstream of the top of the step − margin·H_i]. Where the field forms
  //            when the ice goes on cracking past the lip (docs/measurement.md).
  //   "draped": the other ice past the step: what lay on the ramp and the floor at the start,
  //            where it is at the end. Window [front of the ice that started upstream of the
  //            top of the step, front − margin·H_i]. It cracks as it slides down the ramp.
  //   "auto":  "gate" when the snapshot has gate records, else "final".
  std::string frame = "auto";

  // Window along flow. Final frame: [step_foot_x + margin·H_i, front − margin·H_i]; the margins
  // keep out the step's own bending zone and the front, whose free face cracks differently.
  // Gate frame (initial positions): [gate_x − passed + margin·H_i, gate_x − margin·H_i], i.e.
  // the ice that has passed the gate less its first margin·H_i (the initial front's own face)
  // and its last (only partly through). Explicit bounds are in the frame's coordinates.
  std::optional<double> window_min_x_m;
  std::optional<double> window_max_x_m;
  double window_margin_over_h = 0.5;

  // Neighbouring crevasses closer than this are one feature at this resolution: merged, and
  // the spacing between them is dropped and counted (docs/measurement.md).
  double resolution_floor_over_dx = 3.0;
  // What the floor does to two crevasses closer than it:
  //   "merge": one feature, as above (the deeper one's position and depth);
  //   "drop":  the source study's rule: both are kept, only the spacing between them is dropped
  //            and counted.
  std::string spacing_rule = "merge";
  // Whether an opened gap inside the ice counts as part of a fracture (every frame but the
  // gate's): a cell dx wide with no particle, below the bridged surface and above the bed, in a
  // patch of such cells that borders damaged ice, is filled with damaged points on the particle
  // lattice before the clusters are found. A crack that has opened leaves intact ice on either
  // side and empty cells between them, which the damaged particles alone do not link
  // (docs/measurement.md, "Opened gaps").
  bool count_gaps = false;
  // Whether one damaged cluster that reaches the surface along a damaged skin (a surface layer
  // that lost its strength as the ice stretched) is read as the separate cracks that hang
  // from it: under the skin, each run of surface bins where the cluster reaches at least
  // min_depth below the surface is a crevasse of its own (docs/measurement.md, "Cracks under a
  // damaged skin"). Off: the whole cluster is one crevasse, its deepest crack's depth.
  bool split_under_skin = false;
  // A crevasse shallower than this is not resolved either (a damaged lens one or two particle
  // rows under the surface cannot be told from an opening at this resolution): not counted,
  // and counted in shallow_count instead. 0 counts every surface-reaching cluster.
  double min_depth_over_dx = 3.0;
  // Damaged particles closer than this belong to one crevasse. 2.1 spacings also links across
  // one particle, intact or gone, in a line of damage: an opened fracture is such a broken line,
  // and its measured depth is the same from 2.1 to 3 spacings (docs/measurement.md, step 3).
  double link_distance_over_spacing = 2.1;
  // A damaged cluster is a crevasse when one of its particles comes this close to z_s(x).
  double surface_reach_over_dx = 1.5;
  // Surface profile: moving average over this many dx-bins (odd; 1 = none), and dips narrower
  // than 2 × bridge half-width (crevasse openings) bridged between their lips. The bridge also
  // lifts a concave bend of the surface by about (change of slope) × half-width / 2, so it is
  // kept short: 0.25·H_i (never below dx).
  int surface_smoothing_bins = 3;
  double surface_bridge_half_width_over_h = 0.25;

  // "fragmented" when at least this fraction of the particles in the window is damaged, or
  // when more than this fraction of the window's surface bins has no undamaged particle.
  double fragmented_fraction = 0.5;

  // 3D: only particles with |y − y_c| ≤ band/2 are measured, y_c the middle of the particles'
  // y-range unless given. Two cells hold enough particles to link a crevasse across the band.
  double y_band_width_over_dx = 2.0;
  std::optional<double> y_band_center_m;

  std::optional<double> dx_m;                // bin width; default snapshot.dx_m
  std::optional<double> ice_thickness_m;     // H_i; default snapshot.ice_thickness_m
  std::optional<double> particle_spacing_m;  // default snapshot value, else dx/2
};

// The numbers actually used, recorded with every result.
struct ResolvedMeasureSettings {
  std::string frame = "final";  // "gate", "final", "passed" or "draped"
  double damage_threshold = 0.0;
  double eps_v_p_threshold = 0.0;         // the ε_v^p at which a particle becomes damaged
  bool threshold_from_softening = false;  // false: the absolute ε_v^p threshold was used
  double window_min_x_m = 0.0;
  double window_max_x_m = 0.0;
  bool window_explicit = false;
  double dx_m = 0.0;
  double ice_thickness_m = 0.0;
  double particle_spacing_m = 0.0;
  double resolution_floor_m = 0.0;
  std::string spacing_rule = "merge";
  bool count_gaps = false;
  bool split_under_skin = false;
  double min_depth_m = 0.0;
  double link_distance_m = 0.0;
  double surface_reach_m = 0.0;
  int surface_smoothing_bins = 0;
  double surface_bridge_half_width_m = 0.0;
  // The lips are read this far outside a crevasse's damaged material: far enough that the
  // smoothing window does not reach into the crevasse, (smoothing_bins/2 + 1)·dx.
  double lip_offset_m = 0.0;
  double fragmented_fraction = 0.0;
  int dim = 2;
  double y_band_center_m = 0.0;  // 3D only
  double y_band_width_m = 0.0;   // 3D only
};

struct Crevasse {
  double x_m = 0.0;          // where it meets the surface: mean x of its members near z_s
  double surface_z_m = 0.0;  // local surface at x_m: interpolated between the two lips
  double bottom_z_m = 0.0;   // lowest damaged material (lowest centre − half a spacing)
  double depth_m = 0.0;      // surface_z_m − bottom_z_m
  double width_m = 0.0;      // x-extent of its damaged material near the surface
  std::size_t particle_count = 0;
  std::size_t merged_count = 1;             // clusters merged into it by the resolution floor
  std::optional<double> spacing_to_next_m;  // absent for the most downstream crevasse
};

struct QuartileSummary {
  double q25 = 0.0;
  double median = 0.0;
  double q75 = 0.0;
};
// Quartiles of a non-empty sample, linear between order statistics (Hyndman–Fan type 7, GSL's):
// every stored distribution uses them.
QuartileSummary quartiles(std::vector<double> values);

struct MeasureFlags {
  bool empty_snapshot = false;  // no particles (in the 3D band) at all
  bool empty_window = false;    // window of zero length or holding no particles
  bool no_crevasse = false;     // no crevasse inside the window
  bool fragmented = false;      // see MeasureSettings::fragmented_fraction
  bool has_spacing = false;     // at least one spacing survived the floor
};

struct CrevasseMeasurement {
  ResolvedMeasureSettings settings;
  double time_s = 0.0;
  std::vector<Crevasse> crevasses;  // inside the window, sorted by x, after merging
  std::vector<double> spacings_m;   // between consecutive crevasses, all ≥ the floor
  std::size_t dropped_spacing_count = 0;
  std::size_t shallow_count = 0;  // surface-reaching features shallower than min_depth_m
  std::size_t particle_count = 0;  // particles measured (the band, in 3D)
  std::size_t window_particle_count = 0;
  std::size_t damaged_particle_count = 0;  // of the measured particles
  std::size_t cluster_count = 0;           // damaged clusters anywhere, crevasse or not
  // How broken the window's ice is: the damaged share of its particles, and of those lying more
  // than H_i/2 below the local surface. Surface crevasses of partial depth leave the second
  // near zero; ice shattered under its surface (or cut through by many full-depth fractures)
  // does not. Not a flag: no threshold is part of the measurement.
  std::size_t window_damaged_count = 0;
  std::size_t deep_particle_count = 0;
  std::size_t deep_damaged_count = 0;
  // Statistics are absent (not NaN) when there is nothing to summarise.
  std::optional<QuartileSummary> spacing_m, spacing_over_h;
  std::optional<QuartileSummary> depth_m, depth_over_h;
  MeasureFlags flags;
  SurfaceProfile surface;
};

// The scales of the run a measurement reads. Every length a measurement resolves is tied to them,
// so that no setting can ask for a resolution or thickness the run does not have (and with it an
// unbounded amount of work): dx_m, ice_thickness_m and particle_spacing_m lie within a factor
// kMeasureScaleFactor of the run's own, and the profile has at most kMaxMeasureBins bins along
// the particles' extent. A scale of 0 is unknown and bounds nothing.
struct MeasureScales {
  double dx_m = 0.0;
  double ice_thickness_m = 0.0;
  double particle_spacing_m = 0.0;
};
inline constexpr double kMeasureScaleFactor = 4.0;
inline constexpr double kMaxMeasureBins = 1e6;
// Throws std::invalid_argument naming the setting, its value and the range the run allows.
void check_measure_scales(const MeasureSettings& settings, const MeasureScales& run);

// Called now and then while measuring (between stages, and every few thousand steps of the
// longer loops). A caller that has to stop (a time limit, a signal) throws from it, and the
// measurement is abandoned with that exception. Empty: never called.
using MeasurePoll = std::function<void()>;

// Throws std::invalid_argument with the offending field when the snapshot's arrays disagree in
// length, hold non-finite positions, or dx / H_i are unknown while particles are present, or a
// setting is out of the run's scales (check_measure_scales).
ResolvedMeasureSettings resolve_measure_settings(const ParticleSnapshot& snapshot,
                                                 const MeasureSettings& settings);
CrevasseMeasurement measure_crevasses(const ParticleSnapshot& snapshot,
                                      const MeasureSettings& settings = {}, const MeasurePoll& poll = {});

// The gate records of a snapshot as a snapshot of their own: each recorded particle at its
// initial position with the ε_v^p it had at the gate (velocities and stresses zero). Metadata
// (dx, H_i, ζ, bed, gate) copied; the front is the gate. Throws when there are no records.
ParticleSnapshot gate_frame_snapshot(const ParticleSnapshot& snapshot);
// The frame names MeasureSettings::frame accepts, and the same as one line for messages
// ("'auto', 'gate', 'final', 'passed' or 'draped'"). Study files check their frame against it.
bool is_measure_frame(const std::string& name);
std::string measure_frame_names();
// True when `settings` select the gate frame for this snapshot (throws on a bad frame name or
// on "gate" without gate records).
bool uses_gate_frame(const ParticleSnapshot& snapshot, const MeasureSettings& settings);

// The strength regime's length c/(ρ_i g) spans fewer than 3 cells (the resolution floor): a case
// there cannot show strength-spaced crevasses, so it is flagged and left out of fits by default
// (docs/measurement.md, "Resolution rule").
inline constexpr double kStrengthLengthMinCells = 3.0;
// A study that puts c/(ρ_i g) on the floor itself (Π = 3 dx/H_i) derives c through Π ρ_i g H_i,
// whose round-off must not push it under: the floor holds to this relative tolerance.
inline constexpr double kStrengthFloorTolerance = 1e-9;
inline bool strength_under_resolved(double tensile_strength_pa, double density, double gravity,
                                    double dx_m) {
  return strength_length(tensile_strength_pa, density, gravity) <
         kStrengthLengthMinCells * dx_m * (1.0 - kStrengthFloorTolerance);
}

}  // namespace crevasse::analysis
