#include "engine/scene.hpp"

#include <algorithm>
#include <functional>
#include <type_traits>
#include <cmath>
#include <numbers>
#include <set>

#include "engine/error.hpp"
#include "engine/hencky.hpp"
#include "engine/json_input.hpp"

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

// A number as docs/scene_format.md writes it: 1e5 rather than 100000, − for minus.
std::string doc_number(double v) {
  const double a = std::abs(v);
  std::string body;
  const double e = a > 0 ? std::round(std::log10(a)) : 0;
  if (a > 0 && std::abs(e) >= 3 && a == std::pow(10.0, e)) body = "1e" + std::to_string(static_cast<int>(e));
  else body = input_number(a);
  return (v < 0 ? "−" : "") + body;
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

template <class E>
struct KindNames;
template <>
struct KindNames<Body> {
  static constexpr std::pair<Body, const char*> names[] = {{Body::slab, "slab"}, {Body::box, "box"}};
};
template <>
struct KindNames<BedShape> {
  static constexpr std::pair<BedShape, const char*> names[] = {
      {BedShape::step, "step"}, {BedShape::concave, "concave"}, {BedShape::flat, "flat"}, {BedShape::none, "none"}};
};
template <>
struct KindNames<InitialStress> {
  static constexpr std::pair<InitialStress, const char*> names[] = {{InitialStress::geostatic, "geostatic"},
                                                                    {InitialStress::hydrostatic, "hydrostatic"},
                                                                    {InitialStress::none, "none"}};
};
template <>
struct KindNames<DriveStart> {
  static constexpr std::pair<DriveStart, const char*> names[] = {{DriveStart::ramp, "ramp"},
                                                                 {DriveStart::moving, "moving"}};
};
template <>
struct KindNames<DriveBoundary> {
  static constexpr std::pair<DriveBoundary, const char*> names[] = {{DriveBoundary::piston, "piston"},
                                                                    {DriveBoundary::inflow, "inflow"}};
};

template <class E>
const char* name_of(E k) {
  for (const auto& [v, n] : KindNames<E>::names)
    if (v == k) return n;
  return "?";
}

// 'a', 'b' or 'c'
template <class E>
std::string allowed_names() {
  std::vector<std::string> names;
  for (const auto& [v, n] : KindNames<E>::names) names.push_back(n);
  return name_list(names, true);
}

template <class E>
E kind_from_name(const std::string& field, const std::string& name) {
  for (const auto& [v, n] : KindNames<E>::names)
    if (name == n) return v;
  fail(field, "value '" + name + "' is not " + allowed_names<E>());
}

// When a field's static range is checked: always; for a slab; with the softening effect; or
// never here, because its bounds depend on other fields (SceneConfig::resolve checks those).
// creep: checked only when the ice creeps (ice.creep is an optional section, FieldSpec::written).
enum class When { always, slab, softening, creep, in_resolve };
enum class Part { physics, numerics, run, output };

// One scene field, described once: where it lives in the JSON, its part, type, unit and range.
// The reader, the writer and the range checks below loop over these; the test
// SceneFields.DocsTableMatchesTheFieldTable holds docs/scene_format.md to them.
struct FieldSpec {
  std::string section;  // JSON object holding it: "ice", "ice.softening", "bed", ...
  std::string key;
  Part part;
  std::string type;  // number, integer, boolean, string
  std::string unit;  // as docs/scene_format.md writes it
  When when = When::always;
  double lo = 0, hi = 0;
  bool lo_open = false, hi_open = false;
  std::string derived;  // "0 → 5 H_i": what a default of 0 (or < 0) stands for, for the docs
  std::function<nlohmann::json(const SceneConfig&)> get;
  std::function<void(ObjectReader&, SceneConfig&)> read;
  std::function<double(const SceneConfig&)> number;  // the value the range check reads
  // Empty: always written. Otherwise an optional field, written into a scene only when this
  // holds, so that scenes which do not use it keep the case hash they had before it existed.
  std::function<bool(const SceneConfig&)> written;
  std::string path() const { return section + "." + key; }
};

FieldSpec written_when(FieldSpec f, std::function<bool(const SceneConfig&)> when) {
  f.written = std::move(when);
  return f;
}

template <class Owner>
FieldSpec number_field(std::string section, std::string key, Part part, std::string unit, double Owner::*m,
                       When when, double lo, double hi, bool lo_open = false, bool hi_open = false,
                       std::string derived = "") {
  FieldSpec f{std::move(section), key, part, "number", std::move(unit), when, lo, hi, lo_open, hi_open,
              std::move(derived), {}, {}, {}, {}};
  f.get = [m](const SceneConfig& s) { return nlohmann::json(s.*m); };
  f.read = [m, key](ObjectReader& r, SceneConfig& s) { r.number(key, s.*m); };
  f.number = [m](const SceneConfig& s) { return s.*m; };
  return f;
}

template <class T, class Owner>
FieldSpec integer_field(std::string section, std::string key, Part part, T Owner::*m, When when, double lo,
                        double hi) {
  FieldSpec f{std::move(section), key, part, "integer", "–", when, lo, hi, false, false, "", {}, {}, {}, {}};
  f.get = [m](const SceneConfig& s) { return nlohmann::json(s.*m); };
  f.read = [m, key, path = f.path()](ObjectReader& r, SceneConfig& s) {
    std::int64_t v = static_cast<std::int64_t>(s.*m);
    r.integer(key, v);
    if constexpr (std::is_unsigned_v<T>) {
      if (v < 0) fail(path, "must be ≥ 0");
      s.*m = static_cast<T>(v);
    } else if constexpr (std::is_same_v<T, int>) {
      s.*m = static_cast<int>(std::clamp<std::int64_t>(v, -1, 1000));  // still refused by the range check
    } else {
      s.*m = v;
    }
  };
  f.number = [m](const SceneConfig& s) { return static_cast<double>(s.*m); };
  return f;
}

template <class Owner>
FieldSpec boolean_field(std::string section, std::string key, Part part, bool Owner::*m) {
  FieldSpec f{std::move(section), key, part, "boolean", "", When::in_resolve, 0, 0, false, false, "", {}, {}, {}, {}};
  f.get = [m](const SceneConfig& s) { return nlohmann::json(s.*m); };
  f.read = [m, key](ObjectReader& r, SceneConfig& s) { r.boolean(key, s.*m); };
  return f;
}

template <class E, class Owner>
FieldSpec kind_field(std::string section, std::string key, Part part, E Owner::*m) {
  FieldSpec f{std::move(section), key, part, "string", "", When::in_resolve, 0, 0, false, false, "", {}, {}, {}, {}};
  f.get = [m](const SceneConfig& s) { return nlohmann::json(name_of(s.*m)); };
  f.read = [m, key, path = f.path()](ObjectReader& r, SceneConfig& s) {
    std::string name = name_of(s.*m);
    r.string(key, name);
    s.*m = kind_from_name<E>(path, name);
  };
  return f;
}

const std::vector<FieldSpec>& field_table() {
  using S = SceneConfig;
  constexpr auto P = Part::physics, N = Part::numerics, R = Part::run, O = Part::output;
  constexpr auto A = When::always, Sl = When::slab, So = When::softening, Cr = When::creep, X = When::in_resolve;
  const auto creeping = [](const S& s) { return s.creeps(); };
  static const std::vector<FieldSpec> table = {
      kind_field("ice", "body", P, &S::body),
      number_field("ice", "density", P, "kg/m³", &S::density, A, 1, 1e5),
      number_field("ice", "youngs_modulus", P, "Pa", &S::youngs_modulus, A, 1e3, 1e13),
      number_field("ice", "poisson_ratio", P, "–", &S::poisson_ratio, A, -1, 0.5, true, true),
      number_field("ice", "tensile_strength", P, "Pa", &S::tensile_strength, A, 0, 1e10, true),
      number_field("ice", "shear_strength", P, "Pa", &S::shear_strength, A, 0, 1e12, true),
      number_field("ice", "thickness", P, "m", &S::ice_thickness, Sl, 0, 1e5, true),
      number_field("ice", "upstream_length", P, "m", &S::upstream_length, X, 0, 0, false, false, "5 H_i"),
      number_field("ice", "draped_length", P, "m", &S::draped_length, X, 0, 0),
      number_field("ice", "width", P, "m", &S::width, X, 0, 0, false, false, "H_i"),
      kind_field("ice", "initial_stress", P, &S::initial_stress),
      number_field("ice", "settle_time", N, "s", &S::settle_time, X, 0, 1e6, false, false, "30 h/c_p"),
      number_field("ice.softening", "zeta_ref", P, "–", &S::zeta_ref, So, 0, 1e9, true),
      number_field("ice.softening", "dx_ref", P, "m", &S::dx_ref, So, 0, 1e4, true),
      number_field("ice.softening", "zeta", P, "–", &S::softening_zeta, So, 0, 1e9, false, false, "derived"),
      number_field("ice.softening", "fracture_energy", P, "J/m²", &S::fracture_energy, So, 0, 1e12, false, false,
                   "derived"),
      boolean_field("ice.softening", "damage_softens_shear", P, &S::damage_softens_shear),
      number_field("ice.softening", "residual_friction", P, "–", &S::residual_friction, So, 0, 10),
      written_when(number_field("ice.softening", "nonlocal_radius", P, "m", &S::nonlocal_radius, So, 0, 1e5),
                   [](const S& s) { return s.nonlocal_radius > 0.0; }),
      written_when(number_field("ice.softening", "nonlocal_weight", P, "–", &S::nonlocal_weight, So, 1, 4),
                   [](const S& s) { return s.nonlocal_radius > 0.0; }),
      written_when(number_field("ice.softening", "cap_relaxation_time", P, "s", &S::cap_relaxation_time, So, 0, 1e6),
                   [](const S& s) { return s.cap_relaxation_time > 0.0; }),
      written_when(boolean_field("ice.softening", "brittle_cap", P, &S::brittle_cap),
                   [](const S& s) { return s.brittle_cap; }),
      written_when(number_field("ice.creep", "rate_factor", P, "Pa⁻ⁿ/s", &S::creep_rate_factor, A, 0, 1), creeping),
      written_when(number_field("ice.creep", "exponent", P, "–", &S::creep_exponent, Cr, 1, 6), creeping),
      written_when(number_field("ice.creep", "field_speed", P, "m/s", &S::creep_field_speed, Cr, 0, 1e3, true),
                   creeping),
      kind_field("bed", "shape", P, &S::bed_shape),
      number_field("bed", "step_height", P, "m", &S::step_height, Sl, 0, 1e5),
      number_field("bed", "step_length", P, "m", &S::step_length, Sl, 0, 1e6),
      written_when(number_field("bed", "lip_radius", P, "m", &S::lip_radius, Sl, 0, 1e6),
                   [](const S& s) { return s.lip_radius > 0.0; }),
      number_field("bed", "downstream_length", P, "m", &S::downstream_length, X, 0, 0, false, false, "10 H_i"),
      number_field("bed", "friction", P, "–", &S::bed_friction, A, 0, 10),
      number_field("bed", "z", P, "m", &S::flat_bed_z, X, 0, 0),
      number_field("drive", "speed", P, "m/s", &S::drive_speed, A, 0, 1e3),
      number_field("drive", "ramp_time", P, "s", &S::drive_ramp_time, A, 0, 1e6, false, false, "100 L_up/c_p"),
      kind_field("drive", "start", P, &S::drive_start),
      kind_field("drive", "boundary", P, &S::drive_boundary),
      number_field("gravity", "g", P, "m/s²", &S::gravity, A, 0, 1e3),
      number_field("gravity", "tilt_deg", P, "°", &S::gravity_tilt_deg, A, -90, 90),
      number_field("numerics", "dx", N, "m", &S::dx, A, 1e-3, 1e4),
      integer_field("numerics", "particles_per_cell_axis", N, &S::particles_per_cell_axis, A, 1, 6),
      number_field("numerics", "cfl", N, "–", &S::cfl, A, 0, 2, true),
      number_field("numerics", "jitter", N, "–", &S::jitter, A, 0, 0.5),
      integer_field("numerics", "seed", N, &S::seed, X, 0, 0),
      number_field("numerics", "top_margin", N, "m", &S::top_margin, A, 0, 1e6, false, false, "0.5 H_i + 4 dx"),
      boolean_field("numerics", "volumetric_averaging", N, &S::volumetric_averaging),
      written_when(boolean_field("numerics", "average_total_volume", N, &S::average_total_volume),
                   [](const S& s) { return s.average_total_volume; }),
      written_when(boolean_field("numerics", "average_per_cell", N, &S::average_per_cell),
                   [](const S& s) { return s.average_per_cell; }),
      written_when(number_field("numerics", "average_relaxation_time", N, "s", &S::average_relaxation_time, A, 0, 1e6),
                   [](const S& s) { return s.average_relaxation_time > 0.0; }),
      number_field("run", "end_time", R, "s", &S::end_time, A, 0, 1e9),
      number_field("run", "front_past_step", R, "m", &S::front_past_step, A, 0, 1e9),
      number_field("run", "gate_length", R, "m", &S::gate_length, X, 0, 1e9),
      number_field("run", "gate_offset", R, "m", &S::gate_offset, X, 0, 0),
      integer_field("run", "max_steps", R, &S::max_steps, X, 0, 0),
      number_field("run", "wall_time_limit", O, "s", &S::wall_time_limit, A, 0, 1e9),
      number_field("output", "vtu_interval", O, "s", &S::vtu_interval, A, 0, 1e9),
      boolean_field("output", "png", O, &S::png),
  };
  return table;
}

// The static ranges of the fields checked `when`.
void check_fields(const SceneConfig& s, When when) {
  for (const auto& f : field_table())
    if (f.when == when && f.number) check_range(f.path(), f.number(s), {f.lo, f.hi, f.lo_open, f.hi_open});
}

// The JSON object at a section's path ("ice.softening" → j["ice"]["softening"]).
nlohmann::json& section_of(nlohmann::json& j, const std::string& section) {
  nlohmann::json* at = &j;
  std::size_t from = 0;
  while (true) {
    const std::size_t dot = section.find('.', from);
    at = &(*at)[section.substr(from, dot - from)];
    if (dot == std::string::npos) return *at;
    from = dot + 1;
  }
}

}  // namespace

const char* effect_name(Effect e) {
  for (const auto& [k, n] : kEffectNames)
    if (k == e) return n;
  return "?";
}

Effect effect_from_name(const std::string& name) {
  for (const auto& [k, n] : kEffectNames)
    if (name == n) return k;
  std::vector<std::string> all;
  for (const auto& [k, n] : kEffectNames) all.push_back(n);
  fail("effects", "unknown effect '" + name + "' (allowed: " + name_list(all) + ")");
}

bool SceneConfig::records_gate() const {
  return body == Body::slab && (bed_shape == BedShape::step || bed_shape == BedShape::concave) &&
         has(Effect::plasticity);
}

const char* kind_name(Body k) { return name_of(k); }
const char* kind_name(BedShape k) { return name_of(k); }
const char* kind_name(InitialStress k) { return name_of(k); }
const char* kind_name(DriveStart k) { return name_of(k); }
const char* kind_name(DriveBoundary k) { return name_of(k); }

bool SceneConfig::has(Effect e) const {
  return std::find(effects.begin(), effects.end(), e) != effects.end();
}

double SceneConfig::p_wave_speed() const {
  const auto m = ElasticModuli::from_young_poisson(youngs_modulus, poisson_ratio);
  return std::sqrt(m.p_wave_modulus() / density);
}

double SceneConfig::drive_velocity(double t) const {
  if (drive_start == DriveStart::moving) return drive_speed;
  if (t >= drive_ramp_time || drive_ramp_time <= 0) return drive_speed;
  return 0.5 * drive_speed * (1.0 - std::cos(std::numbers::pi * t / drive_ramp_time));
}

double SceneConfig::drive_position(double t) const {
  const double T = drive_start == DriveStart::moving ? 0.0 : drive_ramp_time;
  if (T <= 0) return drive_speed * t;
  const double tr = std::min(t, T);
  const double ramp = 0.5 * drive_speed * (tr - T / std::numbers::pi * std::sin(std::numbers::pi * tr / T));
  return ramp + drive_speed * std::max(0.0, t - T);
}

double SceneConfig::creep_rate() const {
  if (!creeps()) return 0.0;
  const double speed_up = drive_speed > 0.0 && has(Effect::drive) ? drive_speed / creep_field_speed : 1.0;
  return speed_up * (2.0 / std::sqrt(3.0)) * creep_rate_factor * std::pow(3.0, -0.5 * creep_exponent);
}

double SceneConfig::lip_tangent() const {
  return lip_radius * std::tan(0.5 * std::atan2(step_height, step_length));
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
  check_fields(*this, When::always);
  if (drive_boundary == DriveBoundary::inflow && (body != Body::slab || !has(Effect::drive)))
    fail("drive.boundary", "'inflow' needs ice.body 'slab' and the 'drive' effect");
  if (max_steps < 0) fail("run.max_steps", "must be ≥ 0 (0 = unlimited)");
  if (end_time == 0 && front_past_step == 0 && gate_length == 0 && max_steps == 0)
    fail("run", "give end_time, front_past_step, gate_length or max_steps, or the run never stops");
  if (has(Effect::softening) && !has(Effect::plasticity))
    fail("effects", "'softening' needs 'plasticity'");
  if (nonlocal_radius > 0.0 && !has(Effect::softening))
    fail("ice.softening.nonlocal_radius", "needs the 'softening' effect (it averages what softens)");
  if (nonlocal_radius > 0.0 && nonlocal_radius < dx)
    fail("ice.softening.nonlocal_radius", "value " + input_number(nonlocal_radius) + " m is below dx; allowed 0 or [dx, 1e5] m");
  if (brittle_cap && (cap_relaxation_time > 0.0 || nonlocal_radius > 0.0))
    fail("ice.softening.brittle_cap", "drops the stress at once: not with cap_relaxation_time or nonlocal_radius");
  if (cap_relaxation_time > 0.0 && !has(Effect::plasticity))
    fail("ice.softening.cap_relaxation_time", "needs the 'plasticity' effect");
  if (average_total_volume && !volumetric_averaging)
    fail("numerics.average_total_volume", "needs numerics.volumetric_averaging true (it says what the average takes)");
  if (average_relaxation_time > 0.0 && !average_per_cell)
    fail("numerics.average_relaxation_time", "needs numerics.average_per_cell true (it relaxes the per-cell average)");
  if (average_per_cell && !volumetric_averaging)
    fail("numerics.average_per_cell", "needs numerics.volumetric_averaging true (it says where the average is taken)");
  if (creeps()) {
    if (!has(Effect::plasticity))
      fail("ice.creep.rate_factor", "creep needs the 'plasticity' effect (it relaxes the deviator in the return mapping)");
    check_fields(*this, When::creep);
  }

  // ζ: explicit, from G, or crack-band scaled from the reference (docs/model.md).
  if (has(Effect::softening)) {
    check_fields(*this, When::softening);
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

  if (body == Body::slab) check_fields(*this, When::slab);
  if (settle_time < 0.0) {
    const double h = body == Body::slab ? ice_thickness : box_max[dim - 1] - box_min[dim - 1];
    settle_time = (initial_stress != InitialStress::none && has(Effect::gravity)) ? 30.0 * h / p_wave_speed() : 0.0;
  }
  check_range("ice.settle_time", settle_time, {0.0, 1e6});
  if (body == Body::slab) {
    if (dx > ice_thickness / 4.0)
      fail("numerics.dx", "value " + input_number(dx) + " is too coarse for ice.thickness " +
                              input_number(ice_thickness) + " (need dx ≤ H_i/4 = " + input_number(ice_thickness / 4) + ")");
    if (upstream_length == 0.0) upstream_length = 5.0 * ice_thickness;
    if (downstream_length == 0.0) downstream_length = 10.0 * ice_thickness;
    if (width == 0.0) width = ice_thickness;
    if (top_margin == 0.0) top_margin = 0.5 * ice_thickness + 4.0 * dx;
    if (drive_start == DriveStart::moving) drive_ramp_time = 0.0;
    else if (drive_ramp_time == 0.0 && has(Effect::drive)) drive_ramp_time = 100.0 * upstream_length / p_wave_speed();
    check_range("ice.upstream_length", upstream_length, {2.0 * dx, 1e7});
    // A glacier held downstream drapes the whole bed by default, up to the outflow line.
    if (has(Effect::downstream_drive) && draped_length == 0.0)
      draped_length = step_length + downstream_length - 3.0 * dx;
    // Draped ice may reach the outflow line, 3 cells before the domain's end.
    check_range("ice.draped_length", draped_length, {0.0, step_length + downstream_length - 3.0 * dx});
    check_range("bed.downstream_length", downstream_length, {4.0 * dx, 1e7});
    check_range("ice.width", width, {2.0 * dx, 1e6});
    if (bed_shape != BedShape::step && bed_shape != BedShape::concave)
      fail("bed.shape", std::string("value '") + kind_name(bed_shape) + "' is not 'step' or 'concave' (body 'slab')");
    if (bed_shape == BedShape::concave && step_length <= 0)
      fail("bed.step_length", "must be > 0 for the concave bed");
    if (lip_radius > 0.0) {
      if (bed_shape != BedShape::step) fail("bed.lip_radius", "rounds the lip of bed.shape 'step' only");
      // The arc's tangent points lie lip_tangent() from the corner, on the plateau and the ramp.
      const double room = std::min(upstream_length, std::hypot(step_height, step_length));
      if (lip_tangent() > room)
        fail("bed.lip_radius", "value " + input_number(lip_radius) + " m rounds the lip over " + input_number(lip_tangent()) +
                                   " m each side, more than the " + input_number(room) + " m of plateau or ramp; allowed (0, " +
                                   input_number(room / std::tan(0.5 * std::atan2(step_height, step_length))) + "] m");
    }
    const double x_end = upstream_length + step_length + downstream_length;
    domain_min = {-4.0 * dx, 0.0, -4.0 * dx};
    domain_max = {x_end, width, step_height + ice_thickness + top_margin};
    if (dim == 2) {
      domain_min = {-4.0 * dx, -4.0 * dx, 0.0};
      domain_max = {x_end, step_height + ice_thickness + top_margin, 0.0};
    }
  } else {
    for (int a = 0; a < dim; ++a) {
      const std::string ax = std::to_string(a);
      if (!(box_max[a] > box_min[a])) fail("ice.box_max", "must exceed ice.box_min on axis " + ax);
      if (!(domain_max[a] > domain_min[a])) fail("domain.max", "must exceed domain.min on axis " + ax);
      if (box_min[a] < domain_min[a] || box_max[a] > domain_max[a])
        fail("ice.box_min", "the ice box must lie inside the domain on axis " + ax);
    }
    if (bed_shape != BedShape::flat && bed_shape != BedShape::none)
      fail("bed.shape", std::string("value '") + kind_name(bed_shape) + "' is not 'flat' or 'none' (body 'box')");
  }
  check_range("run.gate_length", gate_length, {0.0, 1e9});
  if (gate_length != 0.0) {
    if (!records_gate())
      fail("run.gate_length", "needs a slab on a 'step' or 'concave' bed with the 'plasticity' effect");
    // A piston consumes the slab behind the step; an inflow feeds it without end.
    if (drive_boundary == DriveBoundary::piston) check_range("run.gate_length", gate_length, {0.0, upstream_length, true});
  }
  check_range("run.gate_offset", gate_offset, {0.0, body == Body::slab ? step_length + downstream_length - 8.0 * dx : 0.0});
  if (has(Effect::downstream_drive)) {
    if (body != Body::slab || !has(Effect::drive) || !has(Effect::outflow))
      fail("effects", "'downstream_drive' needs ice.body 'slab' and the 'drive' and 'outflow' effects");
    // The held cells are the last 5 before the domain's end (Simulation::kDownstreamDriveCells).
    const double reach = step_length + downstream_length - 5.0 * dx;
    if (draped_length < reach)
      fail("ice.draped_length", "value " + input_number(draped_length) + " leaves the downstream drive without ice: " +
                                    "with 'downstream_drive' it must be at least bed.step_length + " +
                                    "bed.downstream_length - 5 dx = " + input_number(reach));
  }
  if (has(Effect::basal_friction) && bed_shape == BedShape::none)
    fail("bed.shape", "'basal_friction' needs a bed");
  for (int a : wall_axes)
    if (a < 0 || a >= dim) fail("domain.wall_axes", "axis " + std::to_string(a) + " is not in [0, dim)");
  if (has(Effect::lateral_walls) && dim != 3) fail("effects", "'lateral_walls' exist in 3D only");
  for (std::size_t i = 0; i < velocity_boxes.size(); ++i)
    for (int a = 0; a < dim; ++a)
      if (!(velocity_boxes[i].max[a] > velocity_boxes[i].min[a]))
        fail("velocity_boxes[" + std::to_string(i) + "].max", "must exceed min on axis " + std::to_string(a));
  // Lattice indices are ints, and 1e9 particles are more than any machine holds.
  for (int a = 0; a < dim; ++a)
    if ((domain_max[a] - domain_min[a]) / dx > 1e6)
      fail("numerics.dx", "value " + input_number(dx) + " gives more than 1e6 cells along axis " + std::to_string(a));
  const double particles = expected_particles();
  if (particles > 1e9)
    fail("numerics.dx", "value " + input_number(dx) + " gives about " + input_number(particles) +
                            " particles (limit 1e9); use a coarser dx or a smaller scene");
}

double SceneConfig::expected_particles() const {
  double particles = std::pow(particles_per_cell_axis, dim);
  for (int a = 0; a < dim; ++a) {
    const double ice = body == Body::box ? box_max[a] - box_min[a]
                       : a == 0      ? upstream_length + draped_length
                       : a == dim - 1 ? ice_thickness
                                      : width;
    particles *= ice / dx;
  }
  return particles;
}

namespace {

// "[a]": built by appending, because g++ 12 warns falsely (-Wrestrict) on "[" + to_string(a).
std::string index_suffix(long a) {
  std::string out = "[";
  out += std::to_string(a);
  out += ']';
  return out;
}

// A key given with a non-null value (ObjectReader treats null as absent).
bool given(const nlohmann::json& j, const char* section, const char* key) {
  if (!j.is_object() || !j.contains(section)) return false;
  const auto& o = j.at(section);
  return o.is_object() && o.contains(key) && !o.at(key).is_null();
}

// Refusals beyond the types and ranges: fields the engine would silently ignore (velocity_boxes
// without the 'velocity_boundaries' effect and the effect without boxes, domain.min/max for a
// slab, domain.wall_axes without 'box_walls' and the effect without axes, a non-zero bed.z for
// a bed that is not flat) and coordinates without a range of their own (domain and velocity-box
// corners within 1e6 cells of 0, velocity-box velocities within ±1000 m/s, a flat bed.z between
// the domain's bottom and the ice box's bottom). `j` is the scene's JSON, `s` what was read from
// it and resolved.
void check_given_fields(const nlohmann::json& j, const SceneConfig& s) {
  const int z = s.dim - 1;
  const std::string axis_z = index_suffix(z);
  // Fields the engine would ignore without a word.
  if (!s.velocity_boxes.empty() && !s.has(Effect::velocity_boundaries))
    fail("velocity_boxes", std::to_string(s.velocity_boxes.size()) +
                                 " box(es) given but effects does not list 'velocity_boundaries', so "
                                 "they would be ignored; add the effect or remove the boxes");
  if (s.has(Effect::velocity_boundaries) && s.velocity_boxes.empty())
    fail("effects", "'velocity_boundaries' needs at least one entry in velocity_boxes");
  if (s.body == Body::slab) {
    for (const char* key : {"min", "max"})
      if (given(j, "domain", key))
        fail(std::string("domain.") + key,
               "allowed with ice.body 'box' only; a slab's domain is derived from ice and bed "
               "(remove domain.min and domain.max)");
  }
  if (!s.wall_axes.empty() && !s.has(Effect::box_walls))
    fail("domain.wall_axes", "given but effects does not list 'box_walls', so the walls would be "
                               "ignored; add the effect or remove wall_axes");
  if (s.has(Effect::box_walls) && s.wall_axes.empty())
    fail("effects", "'box_walls' needs at least one axis in domain.wall_axes");
  if (s.bed_shape != BedShape::flat && given(j, "bed", "z") && s.flat_bed_z != 0.0)
    fail("bed.z", "value " + input_number(s.flat_bed_z) + " given for bed.shape '" + kind_name(s.bed_shape) +
                        "'; bed.z applies to bed.shape 'flat' only (remove it)");

  // Coordinates without a range check in the engine's loader. Lattice indices are ints: every
  // coordinate stays within 1e6 cells of 0, the limit resolve() puts on a domain's extent.
  const double reach = 1e6 * s.dx;
  if (s.body == Body::box) {
    for (int a = 0; a < s.dim; ++a) {
      check_range("domain.min[" + std::to_string(a) + "]", s.domain_min[a], {-reach, reach});
      check_range("domain.max[" + std::to_string(a) + "]", s.domain_max[a], {-reach, reach});
    }
  }
  if (s.bed_shape == BedShape::flat) {
    // The flat bed lies inside the domain and under the ice, not through it.
    const double top = s.body == Body::box ? s.box_min[z] : s.domain_max[z];
    check_range("bed.z", s.flat_bed_z, {s.domain_min[z], top});
  }
  for (std::size_t i = 0; i < s.velocity_boxes.size(); ++i) {
    const auto& b = s.velocity_boxes[i];
    const std::string f = "velocity_boxes[" + std::to_string(i) + "].";
    for (int a = 0; a < s.dim; ++a) {
      const std::string ax = index_suffix(a);
      check_range(f + "min" + ax, b.min[a], {-reach, reach});
      check_range(f + "max" + ax, b.max[a], {-reach, reach});
      check_range(f + "velocity" + ax, b.velocity[a], {-1e3, 1e3});
    }
  }
}

}  // namespace

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
  // The table's sections, each an object of its parent; "ice.softening" is read inside "ice".
  const auto read_section = [&](ObjectReader& o, const std::string& section) {
    for (const auto& f : field_table())
      if (f.section == section) f.read(o, s);
  };
  if (const auto* ice = r.child("ice")) {
    ObjectReader o(*ice, "ice");
    read_section(o, "ice");
    o.vector3("box_min", s.box_min, s.dim);
    o.vector3("box_max", s.box_max, s.dim);
    if (const auto* soft = o.child("softening")) {
      ObjectReader so(*soft, "ice.softening");
      read_section(so, "ice.softening");
      so.refuse_unknown();
    }
    if (const auto* creep = o.child("creep")) {
      ObjectReader co(*creep, "ice.creep");
      read_section(co, "ice.creep");
      co.refuse_unknown();
    }
    o.refuse_unknown();
  }
  for (const char* section : {"bed", "drive", "gravity", "numerics", "run", "output"}) {
    if (const auto* obj = r.child(section)) {
      ObjectReader o(*obj, section);
      read_section(o, section);
      o.refuse_unknown();
    }
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
  r.refuse_unknown();
  s.resolve();
  check_given_fields(j, s);
  return s;
}

namespace {

// The canonical JSON of the fields of the given parts, and of the fields outside the table
// (dim, effects, the box, the domain and the velocity boxes, all physics).
// every_section: also the optional fields of a scene that does not use them.
nlohmann::json scene_json_of(const SceneConfig& s, std::initializer_list<Part> parts, bool every_section = false) {
  using nlohmann::json;
  auto vec = [&](const std::array<double, 3>& v) {
    json a = json::array();
    for (int i = 0; i < s.dim; ++i) a.push_back(v[i]);
    return a;
  };
  json effects = json::array();
  for (Effect e : s.effects) effects.push_back(effect_name(e));
  json j = {{"dim", s.dim}, {"effects", effects}};
  for (const auto& f : field_table()) {
    if (!every_section && f.written && !f.written(s)) continue;
    if (std::find(parts.begin(), parts.end(), f.part) != parts.end()) section_of(j, f.section)[f.key] = f.get(s);
  }
  if (s.body == Body::box) {
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

}  // namespace

nlohmann::json scene_to_json(const SceneConfig& s) {
  nlohmann::json j = scene_json_of(s, {Part::physics, Part::numerics, Part::run, Part::output});
  j["name"] = s.name;
  return j;
}

nlohmann::json scene_reference_json() {
  return scene_json_of(SceneConfig{}, {Part::physics, Part::numerics, Part::run, Part::output}, true);
}

nlohmann::json scene_results_json(const SceneConfig& s) {
  return scene_json_of(s, {Part::physics, Part::numerics, Part::run});
}

std::vector<SceneFieldDoc> scene_field_docs() {
  std::vector<SceneFieldDoc> out;
  const SceneConfig defaults;
  for (const auto& f : field_table()) {
    SceneFieldDoc d{f.path(), f.type, f.unit, "", ""};
    const nlohmann::json v = f.get(defaults);
    d.default_value = v.is_string() ? "`\"" + v.get<std::string>() + "\"`" : v.is_boolean() ? v.dump() : doc_number(v.get<double>());
    if (!f.derived.empty()) d.default_value += " → " + f.derived;
    if (f.number && f.when != When::in_resolve) {
      d.range = std::string(f.lo_open ? "(" : "[") + doc_number(f.lo) + ", " + doc_number(f.hi) + (f.hi_open ? ")" : "]");
    }
    out.push_back(std::move(d));
  }
  return out;
}

}  // namespace crevasse
