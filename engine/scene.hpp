#pragma once
// Everything one simulation needs, in SI units, with every default in one place
// (scene_defaults()). Loaded from a scene JSON file (documented in README.md and
// docs/scene_format.md) or built in code by tests. Unknown keys are refused, so a typo in a
// study file never silently runs the default.
#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace crevasse {

// What a scene calls for. The engine assembles its step from exactly these (docs/model.md).
enum class Effect {
  gravity,              // body force
  drive,                // piston pushing the back face at drive_speed
  basal_friction,       // Coulomb contact with the bed
  lateral_walls,        // free-slip walls at y = 0 and y = width (3D)
  box_walls,            // free-slip walls on the domain faces of the axes in wall_axes
  plasticity,           // capped von Mises return mapping
  softening,            // cap softens with ε_v^p (needs plasticity)
  outflow,              // remove ice that leaves the downstream end
  velocity_boundaries,  // boxes of grid nodes moving at a prescribed velocity
  downstream_drive,     // the ice at the downstream end moves at the drive speed (outflow held)
};
const char* effect_name(Effect e);
Effect effect_from_name(const std::string& name);  // throws InputError

struct VelocityBox {
  std::array<double, 3> min{}, max{};   // initial extent [m] (z is the last used axis)
  std::array<double, 3> velocity{};     // [m/s]; the box moves with it
};

// The kinds a scene chooses between (JSON strings in scene files; kind_name gives them).
enum class Body { slab, box };  // glacier on the plateau; or a box of ice box_min..box_max
enum class BedShape { step, concave, flat, none };
// "geostatic": σ_zz = −ρ g (s − z), lateral K0 σ_zz; "hydrostatic": K0 = 1; "none": unloaded.
enum class InitialStress { geostatic, hydrostatic, none };
// How the glacier starts. ramp: at rest, the drive accelerating over drive_ramp_time. moving:
// once settled, the glacier slides as a rigid body at V_x and the drives run at V_x from t = 0:
// no ramp at all, so nothing in the start grows with the slab's length.
enum class DriveStart { ramp, moving };
// What drives the glacier at its back. piston: the back layer of the slab is pushed at V_x, so
// the slab behind the step is consumed and the push grows with its length. inflow: the grid
// nodes at the back of the domain move at V_x and ice enters there, a copy of the ice just
// inside (engine/inflow.hpp), so the upstream ice is only as long as upstream_length.
enum class DriveBoundary { piston, inflow };
const char* kind_name(Body k);
const char* kind_name(BedShape k);
const char* kind_name(InitialStress k);
const char* kind_name(DriveStart k);
const char* kind_name(DriveBoundary k);

// A scene in four parts. The first three decide what a run computes (the case hash is taken
// over them, engine/scene.cpp); the output part only what it writes and how long it may take.
// docs/scene_format.md is the reference of every field (JSON path, unit, default, range); the
// field table in engine/scene.cpp reads, writes and checks them, and a test holds the two equal.

// The model: the ice, the bed, the drive, gravity, and the effects the step runs.
struct ScenePhysics {
  int dim = 2;
  std::vector<Effect> effects;

  // Ice
  double density = 917.0;             // ρ_i [kg/m³]
  double youngs_modulus = 1.0e9;      // E [Pa]
  double poisson_ratio = 0.3;         // ν [-]
  double tensile_strength = 1.0e6;    // c [Pa], 2D convention p = −(τ_xx + τ_zz)/2
  double shear_strength = 1.0e7;      // q_y [Pa]
  // Softening: ζ = zeta_ref · dx / dx_ref (crack band: same G = c·h/ζ at every dx), unless
  // softening_zeta > 0 is given explicitly or fracture_energy > 0 (then ζ = c·dx/G).
  double zeta_ref = 500.0;
  double dx_ref = 10.0;
  double softening_zeta = 0.0;        // resolved ζ (0 until resolve())
  double fracture_energy = 0.0;       // G [J/m²]; 0 = derived from zeta_ref
  bool damage_softens_shear = true;   // q_y·exp(−ζ ε_v^p) (see capped_von_mises.hpp)
  double residual_friction = 1.2;     // M: damaged ice keeps q ≤ M·p (rubble, φ ≈ 30°)
  // Softening with a length (docs/model.md): the opening the softening reads averaged over a
  // radius R (engine/nonlocal_opening.hpp), with the over-nonlocal weight m; 0 = local.
  double nonlocal_radius = 0.0;       // R [m]
  double nonlocal_weight = 1.0;       // m [-]
  // A viscous (Duvaut–Lions) cap: the opening relaxes onto the cap in τ [s]; 0 = rate-independent.
  double cap_relaxation_time = 0.0;
  // The brittle cap (capped_von_mises.hpp): past the cap the ice drops all its stress.
  bool brittle_cap = false;
  // Creep by Glen's law (docs/model.md, "Creep"), off while the rate factor is 0. The drive's
  // time is the field's sped up by drive.speed / creep_field_speed, so the creep rate is too.
  double creep_rate_factor = 0.0;     // A [Pa^-n s^-1] of the real ice; 0 = no creep
  double creep_exponent = 3.0;        // n
  double creep_field_speed = 3.17e-6; // speed of the real glacier the drive stands for [m/s] (100 m/a)
  bool creeps() const { return creep_rate_factor > 0.0; }

  // Geometry
  Body body = Body::slab;
  double ice_thickness = 100.0;       // H_i [m]
  double upstream_length = 0.0;       // slab length on the plateau [m]; 0 → 5·H_i
  // Ice already draped over the bed past the top of the step, horizontal length [m]: the
  // slab continues with its thickness H_i following the bed (surface z_b(x) + H_i). 0: the
  // slab ends in a cliff at the top of the step (docs/model.md).
  double draped_length = 0.0;
  double width = 0.0;                 // W_i [m] (3D); 0 → H_i
  std::array<double, 3> box_min{}, box_max{};  // body box extent [m]
  InitialStress initial_stress = InitialStress::geostatic;

  // Bed
  BedShape bed_shape = BedShape::step;
  double step_height = 100.0;         // H_s [m]
  double step_length = 100.0;         // L_s [m]; 0 = vertical step
  double lip_radius = 0.0;            // the step's convex lip rounded over this radius [m]; 0 = sharp
  double downstream_length = 0.0;     // floor length past the step [m]; 0 → 10·H_i
  double bed_friction = 0.1;          // μ_b [-]
  double flat_bed_z = 0.0;            // bed flat: its height [m]

  double drive_speed = 4.0;           // V_x [m/s]
  // The piston accelerates smoothly, v = V_x (1 − cos(π t/T))/2 for t < T: an impulsive start
  // sends a ρ c_p V_x ≈ 4 MPa stress wave through the slab, which cracks it everywhere. T much
  // longer than the slab's first period 4 L_up/c_p makes the start quasi-static: the inertial
  // compression ρ L_up V_x π/(2T) is then ~70 kPa and the ringing negligible. 0 → 100 L_up/c_p.
  double drive_ramp_time = 0.0;       // T [s]
  DriveStart drive_start = DriveStart::ramp;
  DriveBoundary drive_boundary = DriveBoundary::piston;
  double gravity = 9.81;              // g [m/s²]
  double gravity_tilt_deg = 0.0;      // tilt of gravity towards +x (incline tests) [deg]

  // Boundaries of box scenes
  std::array<double, 3> domain_min{}, domain_max{};  // body box: explicit domain [m] (slab: derived)
  std::vector<int> wall_axes;         // box_walls: axes with free-slip walls on both faces
  std::vector<VelocityBox> velocity_boxes;
};

// The discretisation and the start-up procedure.
struct SceneNumerics {
  double dx = 10.0;                   // grid spacing [m]
  int particles_per_cell_axis = 2;    // 2 → 4 per cell in 2D, 8 in 3D
  double cfl = 0.5;                   // dt = cfl·dx/(c_p + max|v|)
  double jitter = 0.0;                // random particle offset, fraction of particle spacing
  std::uint64_t seed = 1;             // jitter seed (study replicas)
  double top_margin = 0.0;            // air above the ice [m]; 0 → 0.5·H_i + 4·dx
  // ΔJ-bar: each step's volume change is averaged over the grid stencil before the stress
  // update, which removes the particle-scale pressure checkerboard that quadratic MLS-MPM
  // builds near concentrated loads (the lip of the step) and that cracks the ice spuriously.
  bool volumetric_averaging = true;
  // What the average takes: each step's increment ΔJ (false), or each particle's whole trial
  // elastic volume ratio ΔJ·det F_E (true), which also removes a checkerboard already built up.
  bool average_total_volume = false;
  // Where the average is taken: over each node's stencil and interpolated back (false), or over
  // the particles of each grid cell, every particle of a cell taking the cell's mean (true).
  bool average_per_cell = false;
  // With the per-cell average: each step the cell mean moves the fraction min(1, Δt/τ) towards the
  // stencil's whole-volume average (τ in seconds of simulated time); 0 = not at all.
  double average_relaxation_time = 0.0;
  // Settling: the discrete MPM equilibrium differs slightly from the analytic geostatic state,
  // so an undamped start rings and puts the top particle layer into tension. Before t = 0 the
  // slab settles elastically (no return mapping, so no plastic strain), with the drive at rest
  // and its grid velocity damped at rate γ = c_p/H_i (near-critical for the slab's first
  // vertical mode), for settle_time; then velocities are zeroed and the clock starts.
  double settle_time = -1.0;          // [s]; < 0 → 30·H_i/c_p with geostatic stress, 0 = none
};

// When the run stops (the measurement's window depends on it).
struct SceneRun {
  double end_time = 0.0;              // [s]; 0 → until front_past_step
  double front_past_step = 0.0;       // stop when the front is this far past the step foot [m]
  // Stop once this much ice, as a length along flow, has passed the measurement gate at the top
  // of the step [m]; 0 = off. Only for a slab on a step or concave bed with plasticity.
  double gate_length = 0.0;
  // Where the gate stands past the top of the step, horizontally [m]: 0 records the ice as it
  // reaches the lip (the cliff start, whose blocks break off there); a flowing glacier cracks
  // as it bends over the lip, so its crevasses are recorded a little way down the ramp.
  double gate_offset = 0.0;
  std::int64_t max_steps = 0;         // 0 = unlimited
};

// What a run writes and how long it may take: none of it changes a result.
struct SceneOutput {
  double wall_time_limit = 0.0;       // [s]; 0 = unlimited
  double vtu_interval = 0.0;          // simulated seconds between VTU snapshots; 0 = none
  bool png = true;                    // side view at the end
};

struct SceneConfig : ScenePhysics, SceneNumerics, SceneRun, SceneOutput {
  std::string name = "scene";

  bool has(Effect e) const;
  // Fills derived values (lengths defaulting to multiples of H_i, ζ from dx, the domain) and
  // checks every field; throws InputError naming the field and the allowed range.
  void resolve();
  // Derived quantities (valid after resolve()).
  double step_top_x() const { return upstream_length; }
  // The measurement gate records damage as the ice reaches the top of the step: for a slab on
  // a step or concave bed, with plasticity (docs/measurement.md, "Gate frame").
  bool records_gate() const;
  double gate_x() const { return step_top_x() + gate_offset; }
  double step_foot_x() const { return upstream_length + step_length; }
  double p_wave_speed() const;
  double drive_velocity(double t) const;  // piston speed at time t [m/s]
  double drive_position(double t) const;  // piston face x at time t (0 at t = 0) [m]
  double implied_fracture_energy() const;  // G = c·dx/ζ [J/m²] (band width h = dx)
  // How far the rounded lip's arc reaches from the corner along the plateau and the ramp [m].
  double lip_tangent() const;
  // Particles seeded at the start: the ice box, or the slab, over the particle spacing.
  double expected_particles() const;
  // Equivalent plastic strain rate per q^n in simulated time: (2/√3)·A·(q/√3)^n, Glen's law in
  // von Mises terms, sped up as the drive is (real time when there is no drive); 0 without creep.
  double creep_rate() const;
};

SceneConfig scene_from_json(const nlohmann::json& j);  // resolve()d; throws InputError
nlohmann::json scene_to_json(const SceneConfig& s);    // canonical, every field explicit
// The parts that decide what a run computes (all but the name and SceneOutput): what a case's
// identity, and so its hash, is taken over.
nlohmann::json scene_results_json(const SceneConfig& s);
// The canonical form of a default scene with every optional field written (ice.creep,
// numerics.average_total_volume): the fields a study's JSON pointer may name.
nlohmann::json scene_reference_json();

// One row of the field table, as docs/scene_format.md shows it (the test that holds the docs to
// the table reads these): JSON path, type, unit, default (with what a 0 default stands for) and
// the static range ("" when the range depends on other fields; the docs then say how).
struct SceneFieldDoc {
  std::string path, type, unit, default_value, range;
};
std::vector<SceneFieldDoc> scene_field_docs();

}  // namespace crevasse
