#include "engine/scene.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>
#include <sstream>

#include "engine/error.hpp"
#include "engine/hencky.hpp"

namespace crevasse {
namespace {

constexpr std::pair<Effect, const char*> kEffectNames[] = {
    {Effect::gravity, "gravity"},
    {Effect::drive, "drive"},
    {Effect::basal_friction, "basal_friction"},
    {Effect::lateral_walls, "lateral_walls"},
    {Effect::box_walls, "box_walls"},
    {Effect::plasticity, "plasticity"},
    {Effect::softening, "softening"},
    {Effect::outflow, "outflow"},
    {Effect::velocity_boundaries, "velocity_boundaries"},
    {Effect::downstream_drive, "downstream_drive"},
};

std::string fmt(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

[[noreturn]] void fail(const std::string& field, const std::string& what) {
  throw InputError(field + ": " + what);
}

void check_range(const std::string& field, double v, double lo, double hi, bool lo_open = false,
                 bool hi_open = false) {
  const bool ok = std::isfinite(v) && (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  if (!ok) {
    fail(field, "value " + fmt(v) + " is outside the allowed range " + (lo_open ? "(" : "[") +
                    fmt(lo) + ", " + fmt(hi) + (hi_open ? ")" : "]"));
  }
}

// Reads one JSON object, remembering which keys were used so that unknown ones are refused.
class ObjectReader {
 public:
  ObjectReader(const nlohmann::json& j, std::string path) : j_(j), path_(std::move(path)) {
    if (!j_.is_object()) fail(path_.empty() ? "scene" : path_, "must be a JSON object");
  }
  ~ObjectReader() = default;

  bool has(const std::string& key) {
    used_.insert(key);
    return j_.contains(key) && !j_.at(key).is_null();
  }
  std::string field(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

  void number(const std::string& key, double& out) {
    if (!has(key)) return;
    const auto& v = j_.at(key);
    if (!v.is_number()) fail(field(key), "must be a number, got " + std::string(v.type_name()));
    out = v.get<double>();
    if (!std::isfinite(out)) fail(field(key), "must be finite");
  }
  void integer(const std::string& key, std::int64_t& out) {
    if (!has(key)) return;
    const auto& v = j_.at(key);
    if (!v.is_number_integer()) fail(field(key), "must be an integer, got " + v.dump());
    out = v.get<std::int64_t>();
  }
  void string(const std::string& key, std::string& out) {
    if (!has(key)) return;
    const auto& v = j_.at(key);
    if (!v.is_string()) fail(field(key), "must be a string, got " + std::string(v.type_name()));
    out = v.get<std::string>();
  }
  void boolean(const std::string& key, bool& out) {
    if (!has(key)) return;
    const auto& v = j_.at(key);
    if (!v.is_boolean()) fail(field(key), "must be true or false, got " + v.dump());
    out = v.get<bool>();
  }
  void vector3(const std::string& key, std::array<double, 3>& out, int dim) {
    if (!has(key)) return;
    const auto& v = j_.at(key);
    if (!v.is_array() || static_cast<int>(v.size()) != dim)
      fail(field(key), "must be an array of " + std::to_string(dim) + " numbers");
    out = {0, 0, 0};
    for (int i = 0; i < dim; ++i) {
      if (!v[i].is_number()) fail(field(key), "must contain numbers only");
      out[i] = v[i].get<double>();
    }
  }
  const nlohmann::json* child(const std::string& key) {
    if (!has(key)) return nullptr;
    return &j_.at(key);
  }
  void refuse_unknown() const {
    for (auto it = j_.begin(); it != j_.end(); ++it) {
      if (!used_.count(it.key()))
        fail(field(it.key()), "unknown key (check the spelling; see docs/scene_format.md)");
    }
  }

 private:
  const nlohmann::json& j_;
  std::string path_;
  std::set<std::string> used_;
};

}  // namespace

const char* effect_name(Effect e) {
  for (const auto& [k, n] : kEffectNames)
    if (k == e) return n;
  return "?";
}

Effect effect_from_name(const std::string& name) {
  for (const auto& [k, n] : kEffectNames)
    if (name == n) return k;
  std::string all;
  for (const auto& [k, n] : kEffectNames) all += std::string(all.empty() ? "" : ", ") + n;
  fail("effects", "unknown effect '" + name + "' (allowed: " + all + ")");
}

bool SceneConfig::records_gate() const {
  return body == "slab" && (bed_shape == "step" || bed_shape == "concave") && has(Effect::plasticity);
}

bool SceneConfig::has(Effect e) const {
  return std::find(effects.begin(), effects.end(), e) != effects.end();
}

double SceneConfig::p_wave_speed() const {
  const auto m = ElasticModuli::from_young_poisson(youngs_modulus, poisson_ratio);
  return std::sqrt(m.p_wave_modulus() / density);
}

double SceneConfig::drive_velocity(double t) const {
  if (drive_start == "moving") return drive_speed;
  if (t >= drive_ramp_time || drive_ramp_time <= 0) return drive_speed;
  return 0.5 * drive_speed * (1.0 - std::cos(std::numbers::pi * t / drive_ramp_time));
}

double SceneConfig::drive_position(double t) const {
  const double T = drive_start == "moving" ? 0.0 : drive_ramp_time;
  if (T <= 0) return drive_speed * t;
  const double tr = std::min(t, T);
  const double ramp = 0.5 * drive_speed * (tr - T / std::numbers::pi * std::sin(std::numbers::pi * tr / T));
  return ramp + drive_speed * std::max(0.0, t - T);
}

double SceneConfig::implied_fracture_energy() const {
  return softening_zeta > 0 ? tensile_strength * dx / softening_zeta : 0.0;
}

void SceneConfig::resolve() {
  if (dim != 2 && dim != 3) fail("dim", "value " + std::to_string(dim) + " is not 2 or 3");
  {
    std::set<Effect> seen;
    for (Effect e : effects)
      if (!seen.insert(e).second) fail("effects", std::string("'") + effect_name(e) + "' listed twice");
  }
  check_range("ice.density", density, 1.0, 1e5);
  check_range("ice.youngs_modulus", youngs_modulus, 1e3, 1e13);
  check_range("ice.poisson_ratio", poisson_ratio, -1.0, 0.5, true, true);
  check_range("ice.tensile_strength", tensile_strength, 0.0, 1e10, true);
  check_range("ice.shear_strength", shear_strength, 0.0, 1e12, true);
  check_range("numerics.dx", dx, 1e-3, 1e4);
  if (particles_per_cell_axis < 1 || particles_per_cell_axis > 6)
    fail("numerics.particles_per_cell_axis",
         "value " + std::to_string(particles_per_cell_axis) + " is outside the allowed range [1, 6]");
  check_range("numerics.cfl", cfl, 0.0, 2.0, true);
  check_range("numerics.jitter", jitter, 0.0, 0.5);
  check_range("numerics.top_margin", top_margin, 0.0, 1e6);
  check_range("gravity.g", gravity, 0.0, 1e3);
  check_range("gravity.tilt_deg", gravity_tilt_deg, -90.0, 90.0);
  check_range("drive.speed", drive_speed, 0.0, 1e3);
  check_range("drive.ramp_time", drive_ramp_time, 0.0, 1e6);
  if (drive_start != "ramp" && drive_start != "moving")
    fail("drive.start", "value '" + drive_start + "' is not 'ramp' or 'moving'");
  if (drive_boundary != "piston" && drive_boundary != "inflow")
    fail("drive.boundary", "value '" + drive_boundary + "' is not 'piston' or 'inflow'");
  if (drive_boundary == "inflow" && (body != "slab" || !has(Effect::drive)))
    fail("drive.boundary", "'inflow' needs ice.body 'slab' and the 'drive' effect");
  check_range("bed.friction", bed_friction, 0.0, 10.0);
  check_range("run.end_time", end_time, 0.0, 1e9);
  check_range("run.front_past_step", front_past_step, 0.0, 1e9);
  check_range("run.wall_time_limit", wall_time_limit, 0.0, 1e9);
  check_range("output.vtu_interval", vtu_interval, 0.0, 1e9);
  if (max_steps < 0) fail("run.max_steps", "must be ≥ 0 (0 = unlimited)");
  if (end_time == 0 && front_past_step == 0 && gate_length == 0 && max_steps == 0)
    fail("run", "give end_time, front_past_step, gate_length or max_steps, or the run never stops");
  if (has(Effect::softening) && !has(Effect::plasticity))
    fail("effects", "'softening' needs 'plasticity'");
  if (initial_stress != "geostatic" && initial_stress != "hydrostatic" && initial_stress != "none")
    fail("ice.initial_stress",
         "value '" + initial_stress + "' is not 'geostatic', 'hydrostatic' or 'none'");

  // ζ: explicit, from G, or crack-band scaled from the reference (docs/model.md).
  if (has(Effect::softening)) {
    check_range("ice.softening.zeta", softening_zeta, 0.0, 1e9);
    check_range("ice.softening.fracture_energy", fracture_energy, 0.0, 1e12);
    check_range("ice.softening.zeta_ref", zeta_ref, 0.0, 1e9, true);
    check_range("ice.softening.dx_ref", dx_ref, 0.0, 1e4, true);
    check_range("ice.softening.residual_friction", residual_friction, 0.0, 10.0);
    // ζ from one source only: a scene written by scene_to_json carries the ζ its G implied,
    // which is accepted; a ζ that disagrees with G would be used while G was ignored.
    if (softening_zeta > 0.0 && fracture_energy > 0.0 &&
        std::abs(softening_zeta - tensile_strength * dx / fracture_energy) >
            1e-9 * softening_zeta)
      fail("ice.softening.fracture_energy",
           "give zeta or fracture_energy, not both (zeta " + std::to_string(softening_zeta) +
               " disagrees with c dx / fracture_energy = " +
               std::to_string(tensile_strength * dx / fracture_energy) + ")");
    if (softening_zeta == 0.0) {
      softening_zeta = fracture_energy > 0 ? tensile_strength * dx / fracture_energy
                                           : zeta_ref * dx / dx_ref;
    }
  } else {
    softening_zeta = 0.0;
  }

  if (body == "slab") check_range("ice.thickness", ice_thickness, 0.0, 1e5, true);
  if (settle_time < 0.0) {
    const double h = body == "slab" ? ice_thickness : box_max[dim - 1] - box_min[dim - 1];
    settle_time = (initial_stress != "none" && has(Effect::gravity)) ? 30.0 * h / p_wave_speed() : 0.0;
  }
  check_range("ice.settle_time", settle_time, 0.0, 1e6);
  if (body == "slab") {
    check_range("ice.thickness", ice_thickness, 0.0, 1e5, true);
    if (dx > ice_thickness / 4.0)
      fail("numerics.dx", "value " + fmt(dx) + " is too coarse for ice.thickness " +
                              fmt(ice_thickness) + " (need dx ≤ H_i/4 = " + fmt(ice_thickness / 4) + ")");
    if (upstream_length == 0.0) upstream_length = 5.0 * ice_thickness;
    if (downstream_length == 0.0) downstream_length = 10.0 * ice_thickness;
    if (width == 0.0) width = ice_thickness;
    if (top_margin == 0.0) top_margin = 0.5 * ice_thickness + 4.0 * dx;
    if (drive_start == "moving") drive_ramp_time = 0.0;
    else if (drive_ramp_time == 0.0 && has(Effect::drive)) drive_ramp_time = 100.0 * upstream_length / p_wave_speed();
    check_range("ice.upstream_length", upstream_length, 2.0 * dx, 1e7);
    // A glacier held downstream drapes the whole bed by default, up to the outflow line.
    if (has(Effect::downstream_drive) && draped_length == 0.0)
      draped_length = step_length + downstream_length - 3.0 * dx;
    // Draped ice may reach the outflow line, 3 cells before the domain's end.
    check_range("ice.draped_length", draped_length, 0.0, step_length + downstream_length - 3.0 * dx);
    check_range("bed.downstream_length", downstream_length, 4.0 * dx, 1e7);
    check_range("ice.width", width, 2.0 * dx, 1e6);
    check_range("bed.step_height", step_height, 0.0, 1e5);
    check_range("bed.step_length", step_length, 0.0, 1e6);
    if (bed_shape != "step" && bed_shape != "concave")
      fail("bed.shape", "value '" + bed_shape + "' is not 'step' or 'concave' (body 'slab')");
    if (bed_shape == "concave" && step_length <= 0)
      fail("bed.step_length", "must be > 0 for the concave bed");
    const double x_end = upstream_length + step_length + downstream_length;
    domain_min = {-4.0 * dx, 0.0, -4.0 * dx};
    domain_max = {x_end, width, step_height + ice_thickness + top_margin};
    if (dim == 2) {
      domain_min = {-4.0 * dx, -4.0 * dx, 0.0};
      domain_max = {x_end, step_height + ice_thickness + top_margin, 0.0};
    }
  } else if (body == "box") {
    for (int a = 0; a < dim; ++a) {
      const std::string ax = std::to_string(a);
      if (!(box_max[a] > box_min[a])) fail("ice.box_max", "must exceed ice.box_min on axis " + ax);
      if (!(domain_max[a] > domain_min[a])) fail("domain.max", "must exceed domain.min on axis " + ax);
      if (box_min[a] < domain_min[a] || box_max[a] > domain_max[a])
        fail("ice.box_min", "the ice box must lie inside the domain on axis " + ax);
    }
    if (bed_shape != "flat" && bed_shape != "none")
      fail("bed.shape", "value '" + bed_shape + "' is not 'flat' or 'none' (body 'box')");
  } else {
    fail("ice.body", "value '" + body + "' is not 'slab' or 'box'");
  }
  check_range("run.gate_length", gate_length, 0.0, 1e9);
  if (gate_length != 0.0) {
    if (!records_gate())
      fail("run.gate_length", "needs a slab on a 'step' or 'concave' bed with the 'plasticity' effect");
    // A piston consumes the slab behind the step; an inflow feeds it without end.
    if (drive_boundary == "piston") check_range("run.gate_length", gate_length, 0.0, upstream_length, true);
  }
  check_range("run.gate_offset", gate_offset, 0.0, body == "slab" ? step_length + downstream_length - 8.0 * dx : 0.0);
  if (has(Effect::downstream_drive)) {
    if (body != "slab" || !has(Effect::drive) || !has(Effect::outflow))
      fail("effects", "'downstream_drive' needs ice.body 'slab' and the 'drive' and 'outflow' effects");
    // The held cells are the last 5 before the domain's end (Simulation::kDownstreamDriveCells).
    const double reach = step_length + downstream_length - 5.0 * dx;
    if (draped_length < reach)
      fail("ice.draped_length", "value " + fmt(draped_length) + " leaves the downstream drive without ice: " +
                                    "with 'downstream_drive' it must be at least bed.step_length + " +
                                    "bed.downstream_length - 5 dx = " + fmt(reach));
  }
  if (has(Effect::basal_friction) && bed_shape == "none")
    fail("bed.shape", "'basal_friction' needs a bed");
  for (int a : wall_axes)
    if (a < 0 || a >= dim) fail("domain.wall_axes", "axis " + std::to_string(a) + " is not in [0, dim)");
  if (has(Effect::lateral_walls) && dim != 3) fail("effects", "'lateral_walls' exist in 3D only");
  for (std::size_t i = 0; i < velocity_boxes.size(); ++i)
    for (int a = 0; a < dim; ++a)
      if (!(velocity_boxes[i].max[a] > velocity_boxes[i].min[a]))
        fail("velocity_boxes[" + std::to_string(i) + "].max", "must exceed min on axis " + std::to_string(a));
  // Lattice indices are ints and a particle costs about 0.5 kB: refuse what no machine holds.
  double particles = std::pow(particles_per_cell_axis, dim);
  for (int a = 0; a < dim; ++a) {
    if ((domain_max[a] - domain_min[a]) / dx > 1e6)
      fail("numerics.dx", "value " + fmt(dx) + " gives more than 1e6 cells along axis " + std::to_string(a));
    const double ice = body == "box" ? box_max[a] - box_min[a]
                       : a == 0      ? upstream_length + draped_length
                       : a == dim - 1 ? ice_thickness
                                      : width;
    particles *= ice / dx;
  }
  if (particles > 1e9)
    fail("numerics.dx", "value " + fmt(dx) + " gives about " + fmt(particles) +
                            " particles (limit 1e9); use a coarser dx or a smaller scene");
}

SceneConfig scene_from_json(const nlohmann::json& j) {
  SceneConfig s;
  ObjectReader r(j, "");
  r.string("name", s.name);
  std::int64_t dim = 2;
  r.integer("dim", dim);
  s.dim = static_cast<int>(dim);
  if (dim != 2 && dim != 3) fail("dim", "value " + std::to_string(dim) + " is not 2 or 3");
  if (const auto* e = r.child("effects")) {
    if (!e->is_array()) fail("effects", "must be an array of effect names");
    for (const auto& name : *e) {
      if (!name.is_string()) fail("effects", "must contain strings only");
      s.effects.push_back(effect_from_name(name.get<std::string>()));
    }
  }
  if (const auto* ice = r.child("ice")) {
    ObjectReader o(*ice, "ice");
    o.number("density", s.density);
    o.number("youngs_modulus", s.youngs_modulus);
    o.number("poisson_ratio", s.poisson_ratio);
    o.number("tensile_strength", s.tensile_strength);
    o.number("shear_strength", s.shear_strength);
    o.string("body", s.body);
    o.number("thickness", s.ice_thickness);
    o.number("upstream_length", s.upstream_length);
    o.number("draped_length", s.draped_length);
    o.number("width", s.width);
    o.vector3("box_min", s.box_min, s.dim);
    o.vector3("box_max", s.box_max, s.dim);
    o.string("initial_stress", s.initial_stress);
    o.number("settle_time", s.settle_time);
    if (const auto* soft = o.child("softening")) {
      ObjectReader so(*soft, "ice.softening");
      so.number("zeta_ref", s.zeta_ref);
      so.number("dx_ref", s.dx_ref);
      so.number("zeta", s.softening_zeta);
      so.number("fracture_energy", s.fracture_energy);
      so.boolean("damage_softens_shear", s.damage_softens_shear);
      so.number("residual_friction", s.residual_friction);
      so.refuse_unknown();
    }
    o.refuse_unknown();
  }
  if (const auto* bed = r.child("bed")) {
    ObjectReader o(*bed, "bed");
    o.string("shape", s.bed_shape);
    o.number("step_height", s.step_height);
    o.number("step_length", s.step_length);
    o.number("downstream_length", s.downstream_length);
    o.number("friction", s.bed_friction);
    o.number("z", s.flat_bed_z);
    o.refuse_unknown();
  }
  if (const auto* d = r.child("drive")) {
    ObjectReader o(*d, "drive");
    o.number("speed", s.drive_speed);
    o.number("ramp_time", s.drive_ramp_time);
    o.string("start", s.drive_start);
    o.string("boundary", s.drive_boundary);
    o.refuse_unknown();
  }
  if (const auto* g = r.child("gravity")) {
    ObjectReader o(*g, "gravity");
    o.number("g", s.gravity);
    o.number("tilt_deg", s.gravity_tilt_deg);
    o.refuse_unknown();
  }
  if (const auto* n = r.child("numerics")) {
    ObjectReader o(*n, "numerics");
    o.number("dx", s.dx);
    std::int64_t ppc = s.particles_per_cell_axis;
    o.integer("particles_per_cell_axis", ppc);
    s.particles_per_cell_axis = static_cast<int>(std::clamp<std::int64_t>(ppc, -1, 1000));
    o.number("cfl", s.cfl);
    o.number("jitter", s.jitter);
    std::int64_t seed = static_cast<std::int64_t>(s.seed);
    o.integer("seed", seed);
    if (seed < 0) fail("numerics.seed", "must be ≥ 0");
    s.seed = static_cast<std::uint64_t>(seed);
    o.number("top_margin", s.top_margin);
    o.boolean("volumetric_averaging", s.volumetric_averaging);
    o.refuse_unknown();
  }
  if (const auto* d = r.child("domain")) {
    ObjectReader o(*d, "domain");
    o.vector3("min", s.domain_min, s.dim);
    o.vector3("max", s.domain_max, s.dim);
    if (const auto* w = o.child("wall_axes")) {
      if (!w->is_array()) fail("domain.wall_axes", "must be an array of axis numbers");
      for (const auto& a : *w) {
        if (!a.is_number_integer()) fail("domain.wall_axes", "must contain integers only");
        const auto axis = a.get<std::int64_t>();
        if (axis < 0 || axis > 2) fail("domain.wall_axes", "axis " + std::to_string(axis) + " is not in [0, dim)");
        s.wall_axes.push_back(static_cast<int>(axis));
      }
    }
    o.refuse_unknown();
  }
  if (const auto* vb = r.child("velocity_boxes")) {
    if (!vb->is_array()) fail("velocity_boxes", "must be an array");
    // Each box is tested on every grid node each step: thousands make a run crawl.
    if (vb->size() > 1000)
      fail("velocity_boxes", "holds " + std::to_string(vb->size()) + " boxes; at most 1000");
    for (std::size_t i = 0; i < vb->size(); ++i) {
      ObjectReader o((*vb)[i], "velocity_boxes[" + std::to_string(i) + "]");
      VelocityBox b;
      o.vector3("min", b.min, s.dim);
      o.vector3("max", b.max, s.dim);
      o.vector3("velocity", b.velocity, s.dim);
      o.refuse_unknown();
      s.velocity_boxes.push_back(b);
    }
  }
  if (const auto* run = r.child("run")) {
    ObjectReader o(*run, "run");
    o.number("end_time", s.end_time);
    o.number("front_past_step", s.front_past_step);
    o.number("gate_length", s.gate_length);
    o.number("gate_offset", s.gate_offset);
    o.integer("max_steps", s.max_steps);
    o.number("wall_time_limit", s.wall_time_limit);
    o.refuse_unknown();
  }
  if (const auto* out = r.child("output")) {
    ObjectReader o(*out, "output");
    o.number("vtu_interval", s.vtu_interval);
    o.boolean("png", s.png);
    o.refuse_unknown();
  }
  r.refuse_unknown();
  s.resolve();
  return s;
}

nlohmann::json scene_to_json(const SceneConfig& s) {
  using nlohmann::json;
  auto vec = [&](const std::array<double, 3>& v) {
    json a = json::array();
    for (int i = 0; i < s.dim; ++i) a.push_back(v[i]);
    return a;
  };
  json effects = json::array();
  for (Effect e : s.effects) effects.push_back(effect_name(e));
  json j = {
      {"name", s.name},
      {"dim", s.dim},
      {"effects", effects},
      {"ice",
       {{"density", s.density},
        {"youngs_modulus", s.youngs_modulus},
        {"poisson_ratio", s.poisson_ratio},
        {"tensile_strength", s.tensile_strength},
        {"shear_strength", s.shear_strength},
        {"body", s.body},
        {"thickness", s.ice_thickness},
        {"upstream_length", s.upstream_length},
        {"draped_length", s.draped_length},
        {"width", s.width},
        {"initial_stress", s.initial_stress},
        {"settle_time", s.settle_time},
        {"softening",
         {{"zeta_ref", s.zeta_ref},
          {"dx_ref", s.dx_ref},
          {"zeta", s.softening_zeta},
          {"fracture_energy", s.fracture_energy},
          {"damage_softens_shear", s.damage_softens_shear},
          {"residual_friction", s.residual_friction}}}}},
      {"bed",
       {{"shape", s.bed_shape},
        {"step_height", s.step_height},
        {"step_length", s.step_length},
        {"downstream_length", s.downstream_length},
        {"friction", s.bed_friction},
        {"z", s.flat_bed_z}}},
      {"drive", {{"speed", s.drive_speed}, {"ramp_time", s.drive_ramp_time}, {"start", s.drive_start}, {"boundary", s.drive_boundary}}},
      {"gravity", {{"g", s.gravity}, {"tilt_deg", s.gravity_tilt_deg}}},
      {"numerics",
       {{"dx", s.dx},
        {"particles_per_cell_axis", s.particles_per_cell_axis},
        {"cfl", s.cfl},
        {"jitter", s.jitter},
        {"seed", s.seed},
        {"top_margin", s.top_margin},
        {"volumetric_averaging", s.volumetric_averaging}}},
      {"run",
       {{"end_time", s.end_time},
        {"front_past_step", s.front_past_step},
        {"gate_length", s.gate_length},
        {"gate_offset", s.gate_offset},
        {"max_steps", s.max_steps},
        {"wall_time_limit", s.wall_time_limit}}},
      {"output", {{"vtu_interval", s.vtu_interval}, {"png", s.png}}},
  };
  if (s.body == "box") {
    j["ice"]["box_min"] = vec(s.box_min);
    j["ice"]["box_max"] = vec(s.box_max);
    j["domain"] = {{"min", vec(s.domain_min)}, {"max", vec(s.domain_max)}, {"wall_axes", s.wall_axes}};
  } else if (!s.wall_axes.empty()) {
    j["domain"] = {{"wall_axes", s.wall_axes}};
  }
  if (!s.velocity_boxes.empty()) {
    json vb = json::array();
    for (const auto& b : s.velocity_boxes)
      vb.push_back({{"min", vec(b.min)}, {"max", vec(b.max)}, {"velocity", vec(b.velocity)}});
    j["velocity_boxes"] = vb;
  }
  return j;
}

}  // namespace crevasse
