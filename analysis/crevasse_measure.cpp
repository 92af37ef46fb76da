#include "analysis/crevasse_measure.hpp"

#include <gsl/gsl_statistics_double.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <string>

#include "analysis/cracks_under_skin.hpp"
#include "analysis/damage_clusters.hpp"
#include "analysis/damage_criterion.hpp"
#include "analysis/opened_gaps.hpp"
#include "engine/json_input.hpp"

namespace crevasse::analysis {

QuartileSummary quartiles(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  // GSL interpolates linearly between order statistics (Hyndman–Fan type 7).
  return {gsl_stats_quantile_from_sorted_data(values.data(), 1, values.size(), 0.25),
          gsl_stats_quantile_from_sorted_data(values.data(), 1, values.size(), 0.50),
          gsl_stats_quantile_from_sorted_data(values.data(), 1, values.size(), 0.75)};
}

namespace {

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument("crevasse measurement: " + message);
}

void require_positive(double value, const char* field) {
  require(value > 0.0 && std::isfinite(value),
          std::string(field) + " must be finite and > 0, got " + std::to_string(value));
}

void require_non_negative(double value, const char* field) {
  require(value >= 0.0 && std::isfinite(value),
          std::string(field) + " must be finite and >= 0, got " + std::to_string(value));
}

void check_arrays(const ParticleSnapshot& s) {
  const std::size_t n = s.x.size();
  require(s.dim == 2 || s.dim == 3, "snapshot dim must be 2 or 3, got " + std::to_string(s.dim));
  require(s.z.size() == n, "snapshot z has " + std::to_string(s.z.size()) + " entries but x has " +
                               std::to_string(n));
  require(s.eps_v_p.size() == n, "snapshot eps_v_p has " + std::to_string(s.eps_v_p.size()) +
                                     " entries but x has " + std::to_string(n));
  if (s.dim == 3) {
    require(s.y.size() == n, "3D snapshot y has " + std::to_string(s.y.size()) +
                                 " entries but x has " + std::to_string(n));
  }
}

QuartileSummary scaled(QuartileSummary q, double factor) {
  return {q.q25 * factor, q.median * factor, q.q75 * factor};
}

// Per damaged cluster, what the crevasse test and the crevasse record need.
struct ClusterTally {
  std::size_t particle_count = 0;
  double z_min = std::numeric_limits<double>::infinity();
  std::size_t surface_count = 0;  // members within reach of the surface
  double surface_x_sum = 0.0;
  double surface_x_min = std::numeric_limits<double>::infinity();
  double surface_x_max = -std::numeric_limits<double>::infinity();
  bool under_skin = false;  // an opening of a cluster read as cracks under a damaged skin
  bool placed_by_gaps = false;  // no damaged particle reaches the surface: an opened top
};

// A crevasse during merging: its x-extent at the surface is kept to form the union.
struct Candidate {
  Crevasse crevasse;
  double left_m = 0.0;
  double right_m = 0.0;
};

}  // namespace

namespace {
constexpr const char* kFrames[] = {"auto", "gate", "final", "passed", "draped"};
}  // namespace

bool is_measure_frame(const std::string& name) {
  return std::find(std::begin(kFrames), std::end(kFrames), name) != std::end(kFrames);
}

std::string measure_frame_names() { return name_list({std::begin(kFrames), std::end(kFrames)}, true); }

void check_measure_scales(const MeasureSettings& settings, const MeasureScales& run) {
  const auto within = [](const std::optional<double>& value, double scale, const char* key, const char* symbol) {
    if (!value || !(scale > 0.0)) return;
    const double lo = scale / kMeasureScaleFactor, hi = scale * kMeasureScaleFactor;
    if (!(*value >= lo && *value <= hi)) {
      char text[320];
      std::snprintf(text, sizeof text,
                    "%s = %.6g m is outside [%s/4, 4 %s] = [%.6g, %.6g] m of the run it measures (%s = %.6g m)", key,
                    *value, symbol, symbol, lo, hi, symbol, scale);
      throw std::invalid_argument(text);
    }
  };
  within(settings.dx_m, run.dx_m, "dx_m", "dx");
  within(settings.ice_thickness_m, run.ice_thickness_m, "ice_thickness_m", "H_i");
  within(settings.particle_spacing_m, run.particle_spacing_m, "particle_spacing_m", "spacing");
}

bool uses_gate_frame(const ParticleSnapshot& snapshot, const MeasureSettings& settings) {
  require(is_measure_frame(settings.frame),
          "frame must be " + measure_frame_names() + ", got '" + settings.frame + "'");
  if (settings.frame == "passed" || settings.frame == "draped")
    require(snapshot.upstream_ice_front_x_m > 0.0 || snapshot.size() == 0,
            "frame '" + settings.frame +
                "' needs a snapshot that knows where the ice came from (a slab scene with a gate)");
  if (settings.frame == "gate")
    require(snapshot.has_gate(), "frame 'gate' needs a snapshot with gate records (a slab on a "
                                 "step or concave bed, with plasticity)");
  return settings.frame == "gate" || (settings.frame == "auto" && snapshot.has_gate());
}

ParticleSnapshot gate_frame_snapshot(const ParticleSnapshot& s) {
  require(s.has_gate(), "the snapshot has no gate records");
  const std::size_t n = s.gate_eps_v_p.size();
  require(s.gate_x_ref.size() == n && s.gate_z_ref.size() == n &&
              (s.dim == 2 || s.gate_y_ref.size() == n),
          "the snapshot's gate record arrays differ in length");
  ParticleSnapshot g;
  g.dim = s.dim;
  g.time_s = s.time_s;
  g.dx_m = s.dx_m;
  g.softening_zeta = s.softening_zeta;
  g.tensile_strength_pa = s.tensile_strength_pa;
  g.ice_thickness_m = s.ice_thickness_m;
  g.step_top_x_m = s.step_top_x_m;
  g.step_foot_x_m = s.step_foot_x_m;
  g.particle_spacing_m = s.particle_spacing_m;
  g.bed_profile = s.bed_profile;
  g.gate_x_m = s.gate_x_m;
  g.gate_passed_length_m = s.gate_passed_length_m;
  g.ice_front_x_m = s.gate_x_m;
  g.x = s.gate_x_ref;
  g.z = s.gate_z_ref;
  if (s.dim == 3) g.y = s.gate_y_ref;
  g.eps_v_p = s.gate_eps_v_p;
  g.vx.assign(n, 0.0);
  g.vz.assign(n, 0.0);
  if (s.dim == 3) g.vy.assign(n, 0.0);
  g.pressure_pa.assign(n, 0.0);
  g.von_mises_pa.assign(n, 0.0);
  g.sigma_zz_pa.assign(n, 0.0);
  g.volume_m3.assign(n, 0.0);
  return g;
}

namespace {

ResolvedMeasureSettings resolve_in_frame(const ParticleSnapshot& snapshot,
                                         const MeasureSettings& settings, bool gate) {
  check_arrays(snapshot);
  const bool has_particles = snapshot.size() > 0;
  ResolvedMeasureSettings r;
  r.dim = snapshot.dim;
  r.damage_threshold = settings.damage_threshold;
  const DamageCriterion criterion = DamageCriterion::for_snapshot(
      snapshot, settings.damage_threshold, settings.eps_v_p_threshold);
  r.eps_v_p_threshold = criterion.eps_v_p_at_threshold();
  r.threshold_from_softening = criterion.uses_softening();

  r.dx_m = settings.dx_m.value_or(snapshot.dx_m);
  r.ice_thickness_m = settings.ice_thickness_m.value_or(snapshot.ice_thickness_m);
  if (has_particles) {
    require_positive(r.dx_m, "dx (snapshot dx_m or MeasureSettings::dx_m)");
    require_positive(
        r.ice_thickness_m,
        "ice thickness H_i (snapshot ice_thickness_m or MeasureSettings::ice_thickness_m)");
  }
  const double spacing_default =
      snapshot.particle_spacing_m > 0.0 ? snapshot.particle_spacing_m : 0.5 * r.dx_m;
  r.particle_spacing_m = settings.particle_spacing_m.value_or(spacing_default);
  if (has_particles) {
    require_positive(r.particle_spacing_m,
                     "particle spacing (snapshot particle_spacing_m or MeasureSettings)");
    check_measure_scales(settings, {snapshot.dx_m, snapshot.ice_thickness_m, snapshot.particle_spacing_m});
    const auto [lo, hi] = std::minmax_element(snapshot.x.begin(), snapshot.x.end());
    require((*hi - *lo) / r.dx_m <= kMaxMeasureBins,
            "dx_m = " + std::to_string(r.dx_m) + " m would cut the particles' " + std::to_string(*hi - *lo) +
                " m into more than 1e6 bins");
  }

  require_non_negative(settings.resolution_floor_over_dx, "resolution_floor_over_dx");
  require_non_negative(settings.min_depth_over_dx, "min_depth_over_dx");
  require_positive(settings.link_distance_over_spacing, "link_distance_over_spacing");
  require_non_negative(settings.surface_reach_over_dx, "surface_reach_over_dx");
  require_non_negative(settings.window_margin_over_h, "window_margin_over_h");
  // Up to H_i either side: an opening wider than twice the ice is no crevasse, and the bridging's
  // work grows with the square of its width in bins.
  require(settings.surface_bridge_half_width_over_h >= 0.0 && settings.surface_bridge_half_width_over_h <= 1.0,
          "surface_bridge_half_width_over_h must lie in [0, 1], got " +
              std::to_string(settings.surface_bridge_half_width_over_h));
  require(settings.surface_smoothing_bins >= 1 && settings.surface_smoothing_bins % 2 == 1,
          "surface_smoothing_bins must be an odd number >= 1 (centred average), got " +
              std::to_string(settings.surface_smoothing_bins));
  require(settings.fragmented_fraction > 0.0 && settings.fragmented_fraction <= 1.0,
          "fragmented_fraction must lie in (0, 1], got " +
              std::to_string(settings.fragmented_fraction));
  r.resolution_floor_m = settings.resolution_floor_over_dx * r.dx_m;
  if (settings.spacing_rule != "merge" && settings.spacing_rule != "drop")
    throw std::invalid_argument("spacing_rule: value \"" + settings.spacing_rule +
                                "\" is not \"merge\" or \"drop\"");
  r.spacing_rule = settings.spacing_rule;
  r.count_gaps = settings.count_gaps && !gate;
  r.split_under_skin = settings.split_under_skin;
  r.min_depth_m = settings.min_depth_over_dx * r.dx_m;
  r.link_distance_m = settings.link_distance_over_spacing * r.particle_spacing_m;
  r.surface_reach_m = settings.surface_reach_over_dx * r.dx_m;
  r.surface_smoothing_bins = settings.surface_smoothing_bins;
  // Never narrower than one bin either side, so a one-bin crevasse is always bridged.
  r.surface_bridge_half_width_m =
      std::max(settings.surface_bridge_half_width_over_h * r.ice_thickness_m, r.dx_m);
  r.lip_offset_m = (settings.surface_smoothing_bins / 2 + 1) * r.dx_m;
  r.fragmented_fraction = settings.fragmented_fraction;

  const double margin = settings.window_margin_over_h * r.ice_thickness_m;
  r.window_explicit = settings.window_min_x_m.has_value() || settings.window_max_x_m.has_value();
  r.frame = gate ? "gate" : (settings.frame == "passed" || settings.frame == "draped") ? settings.frame : "final";
  if (r.frame == "passed") {
    r.window_min_x_m = settings.window_min_x_m.value_or(snapshot.step_top_x_m + margin);
    r.window_max_x_m = settings.window_max_x_m.value_or(snapshot.upstream_ice_front_x_m - margin);
  } else if (r.frame == "draped") {
    // The passed window stops margin·H_i short of the same point: the first ice over the lip,
    // in between, is the start-up transient and belongs to neither.
    r.window_min_x_m = settings.window_min_x_m.value_or(snapshot.upstream_ice_front_x_m);
    r.window_max_x_m = settings.window_max_x_m.value_or(snapshot.front_x() - margin);
  } else if (gate) {
    r.window_min_x_m =
        settings.window_min_x_m.value_or(snapshot.gate_x_m - snapshot.gate_passed_length_m + margin);
    r.window_max_x_m = settings.window_max_x_m.value_or(snapshot.gate_x_m - margin);
  } else {
    r.window_min_x_m = settings.window_min_x_m.value_or(snapshot.step_foot_x_m + margin);
    r.window_max_x_m = settings.window_max_x_m.value_or(snapshot.front_x() - margin);
  }
  require(std::isfinite(r.window_min_x_m) && std::isfinite(r.window_max_x_m),
          "window bounds must be finite");

  if (snapshot.dim == 3) {
    require_positive(settings.y_band_width_over_dx, "y_band_width_over_dx");
    r.y_band_width_m = settings.y_band_width_over_dx * r.dx_m;
    if (settings.y_band_center_m) {
      r.y_band_center_m = *settings.y_band_center_m;
    } else if (has_particles) {
      const auto [lo, hi] = std::minmax_element(snapshot.y.begin(), snapshot.y.end());
      r.y_band_center_m = 0.5 * (*lo + *hi);
    }
  }
  return r;
}

CrevasseMeasurement measure_in_frame(const ParticleSnapshot& snapshot,
                                     const MeasureSettings& settings, bool gate, const MeasurePoll& poll);

}  // namespace

ResolvedMeasureSettings resolve_measure_settings(const ParticleSnapshot& snapshot,
                                                 const MeasureSettings& settings) {
  if (uses_gate_frame(snapshot, settings))
    return resolve_in_frame(gate_frame_snapshot(snapshot), settings, true);
  return resolve_in_frame(snapshot, settings, false);
}

CrevasseMeasurement measure_crevasses(const ParticleSnapshot& snapshot,
                                      const MeasureSettings& settings, const MeasurePoll& poll) {
  if (uses_gate_frame(snapshot, settings))
    return measure_in_frame(gate_frame_snapshot(snapshot), settings, true, poll);
  return measure_in_frame(snapshot, settings, false, poll);
}

namespace {

CrevasseMeasurement measure_in_frame(const ParticleSnapshot& snapshot,
                                     const MeasureSettings& settings, bool gate, const MeasurePoll& poll) {
  const auto checkpoint = [&] {
    if (poll) poll();
  };
  checkpoint();
  CrevasseMeasurement m;
  m.settings = resolve_in_frame(snapshot, settings, gate);
  m.time_s = snapshot.time_s;
  const ResolvedMeasureSettings& r = m.settings;
  const DamageCriterion criterion = DamageCriterion::for_snapshot(
      snapshot, settings.damage_threshold, settings.eps_v_p_threshold);

  // The measured particles in the (x, z) plane: all of them in 2D, the central y-band in 3D.
  std::vector<double> px, pz;
  std::vector<std::uint8_t> damaged;
  px.reserve(snapshot.size());
  pz.reserve(snapshot.size());
  damaged.reserve(snapshot.size());
  for (std::size_t i = 0; i < snapshot.size(); ++i) {
    if (snapshot.dim == 3 && std::abs(snapshot.y[i] - r.y_band_center_m) > 0.5 * r.y_band_width_m) {
      continue;
    }
    require(std::isfinite(snapshot.x[i]) && std::isfinite(snapshot.z[i]),
            "particle " + std::to_string(i) + " has a non-finite position; the snapshot is " +
                "from a diverged run and cannot be measured");
    px.push_back(snapshot.x[i]);
    pz.push_back(snapshot.z[i]);
    damaged.push_back(criterion.is_damaged(snapshot.eps_v_p[i]) ? 1 : 0);
  }
  m.particle_count = px.size();
  m.damaged_particle_count =
      static_cast<std::size_t>(std::count(damaged.begin(), damaged.end(), 1));
  const bool window_has_length = r.window_max_x_m > r.window_min_x_m;
  auto in_window = [&](double x) { return x >= r.window_min_x_m && x <= r.window_max_x_m; };

  if (px.empty()) {
    m.flags.empty_snapshot = true;
    m.flags.empty_window = true;
    m.flags.no_crevasse = true;
    return m;
  }

  const double half_spacing = 0.5 * r.particle_spacing_m;
  m.surface = compute_surface_profile(px, pz, damaged,
                                      {.bin_width_m = r.dx_m,
                                       .bridge_half_width_m = r.surface_bridge_half_width_m,
                                       .smoothing_bins = r.surface_smoothing_bins,
                                       .particle_half_extent_m = half_spacing,
                                       .poll = poll});
  checkpoint();

  // Window occupancy and the share of it that is broken, for the "fragmented" flag.
  std::size_t window_damaged = 0;
  std::vector<std::uint8_t> bin_has_intact(m.surface.size(), 0);
  std::vector<std::uint8_t> bin_has_any(m.surface.size(), 0);
  for (std::size_t p = 0; p < px.size(); ++p) {
    if (!window_has_length || !in_window(px[p])) continue;
    ++m.window_particle_count;
    window_damaged += damaged[p];
    if (m.surface.height_at(px[p]) - pz[p] > 0.5 * r.ice_thickness_m) {
      ++m.deep_particle_count;
      m.deep_damaged_count += damaged[p];
    }
    const auto b = std::min(
        m.surface.size() - 1,
        static_cast<std::size_t>(std::max(0.0, std::floor((px[p] - m.surface.x0_m) / r.dx_m))));
    bin_has_any[b] = 1;
    if (!damaged[p]) bin_has_intact[b] = 1;
  }
  m.flags.empty_window = m.window_particle_count == 0;
  m.window_damaged_count = window_damaged;
  if (!m.flags.empty_window) {
    const auto occupied = std::count(bin_has_any.begin(), bin_has_any.end(), 1);
    const auto broken = occupied - std::count(bin_has_intact.begin(), bin_has_intact.end(), 1);
    const double n_window = static_cast<double>(m.window_particle_count);
    m.flags.fragmented =
        static_cast<double>(window_damaged) >= r.fragmented_fraction * n_window ||
        static_cast<double>(broken) > r.fragmented_fraction * static_cast<double>(occupied);
  }

  const std::size_t particle_total = px.size();  // gap points, if any, come after the particles
  if (r.count_gaps) {  // after the counts above, which are of particles only
    const GapPoints gaps =
        find_opened_gaps(px, pz, damaged, m.surface, snapshot.bed_profile, r.dx_m, r.particle_spacing_m);
    px.insert(px.end(), gaps.x.begin(), gaps.x.end());
    pz.insert(pz.end(), gaps.z.begin(), gaps.z.end());
    damaged.insert(damaged.end(), gaps.x.size(), 1);
  }
  checkpoint();
  const DamageClusters clusters = find_damage_clusters(px, pz, damaged, r.link_distance_m, poll);
  m.cluster_count = clusters.count;
  checkpoint();
  // Each place where a damaged cluster meets the surface is a crevasse of its own: one cluster
  // may reach the surface at several openings separated by intact surface, when crevasses branch
  // from one root or are joined at depth (by a damaged layer along the bed, say). A cluster's
  // particles belong to the nearest opening along x (within half a particle spacing of the
  // midpoint between two, to both), and an opening's depth is the lowest of its particles.
  std::vector<std::vector<double>> surface_x(clusters.count);
  auto reaches_surface = [&](std::size_t p) {
    return pz[p] + half_spacing >= m.surface.height_at(px[p]) - r.surface_reach_m;
  };
  // The surface in bins one particle spacing wide, each with its topmost particle. An opening
  // is a run of bins whose topmost particle is damaged; two openings of one cluster are apart
  // only where a bin between them has intact ice on top (a wide-open crevasse has none between
  // its walls; a strip of intact ice one particle wide is one). Inclined crevasses side by side
  // overlap in x within the surface reach below such a strip, so the reach alone cannot part them.
  const double top_bin = r.particle_spacing_m;
  const auto top_bins = static_cast<std::size_t>(
      std::ceil(static_cast<double>(m.surface.size()) * r.dx_m / top_bin)) + 1;
  auto bin_of = [&](double x) {
    return std::min(top_bins - 1,
                    static_cast<std::size_t>(std::max(0.0, std::floor((x - m.surface.x0_m) / top_bin))));
  };
  constexpr std::size_t kNoParticle = static_cast<std::size_t>(-1);
  std::vector<std::size_t> topmost(top_bins, kNoParticle);
  for (std::size_t p = 0; p < px.size(); ++p) {
    std::size_t& t = topmost[bin_of(px[p])];
    if (t == kNoParticle || pz[p] > pz[t]) t = p;
  }
  std::vector<std::uint8_t> intact_top(top_bins, 0);
  std::vector<std::vector<double>> top_x(clusters.count);
  for (std::size_t t : topmost) {
    if (t == kNoParticle || !reaches_surface(t)) continue;
    if (!damaged[t]) intact_top[bin_of(px[t])] = 1;
    else top_x[static_cast<std::size_t>(clusters.label[t])].push_back(px[t]);
  }
  // Where a crevasse is: its damaged particles at the surface. Gap points join the walls of an
  // opened crack and carry its depth, but place it only where no damaged particle reaches the
  // surface (the notch a parted crack leaves beside it would pull the position off the crack).
  for (std::size_t p = 0; p < particle_total; ++p) {
    const auto c = clusters.label[p];
    if (c != DamageClusters::kNone && reaches_surface(p)) surface_x[static_cast<std::size_t>(c)].push_back(px[p]);
  }
  std::vector<std::uint8_t> placed_by_particles(clusters.count, 0);
  for (std::size_t c = 0; c < clusters.count; ++c) placed_by_particles[c] = !surface_x[c].empty();
  for (std::size_t p = particle_total; p < px.size(); ++p) {
    const auto c = clusters.label[p];
    if (c != DamageClusters::kNone && !placed_by_particles[static_cast<std::size_t>(c)] && reaches_surface(p))
      surface_x[static_cast<std::size_t>(c)].push_back(px[p]);
  }
  auto intact_between = [&](double a, double b) {
    for (std::size_t k = bin_of(a) + 1; k < bin_of(b); ++k)
      if (intact_top[k]) return true;
    return false;
  };
  // Openings per cluster, as [first, last) into `tally`, and the x boundaries between them; a
  // cluster that reaches the surface only under intact ice has one opening.
  std::vector<ClusterTally> tally;
  std::vector<std::size_t> first(clusters.count + 1, 0);
  std::vector<std::vector<double>> bounds(clusters.count);
  // Under a damaged skin, each crack is an opening of its own, at the surface above it. The
  // skin is ice: its cracks are as deep as they reach below its top, the surface of all the
  // particles (the profile above is of the intact ones, the skin's base).
  SurfaceProfile skin_top;
  std::vector<std::vector<std::pair<double, double>>> cracks(clusters.count);
  if (r.split_under_skin) {
    skin_top = compute_surface_profile(px, pz, std::vector<std::uint8_t>(px.size(), 0),
                                       {.bin_width_m = r.dx_m,
                                        .bridge_half_width_m = r.surface_bridge_half_width_m,
                                        .smoothing_bins = r.surface_smoothing_bins,
                                        .particle_half_extent_m = half_spacing});
    cracks = cracks_under_skin(px, pz, clusters, skin_top, m.surface.x0_m, top_bin, r.min_depth_m);
  }
  for (std::size_t c = 0; c < clusters.count; ++c) {
    first[c] = tally.size();
    auto& xs = surface_x[c];
    if (!cracks[c].empty())
      std::erase_if(xs, [&](double x) {
        return std::none_of(cracks[c].begin(), cracks[c].end(),
                            [x](const auto& k) { return x >= k.first && x < k.second; });
      });
    if (xs.empty()) continue;
    std::sort(xs.begin(), xs.end());
    auto& tops = top_x[c];
    std::sort(tops.begin(), tops.end());
    for (std::size_t i = 1; i < tops.size(); ++i)
      if (tops[i] - tops[i - 1] > r.link_distance_m && intact_between(tops[i - 1], tops[i]))
        bounds[c].push_back(0.5 * (tops[i] + tops[i - 1]));
    for (std::size_t i = 1; i < cracks[c].size(); ++i)
      bounds[c].push_back(0.5 * (cracks[c][i - 1].second + cracks[c][i].first));
    std::sort(bounds[c].begin(), bounds[c].end());
    tally.resize(tally.size() + bounds[c].size() + 1);
    if (!cracks[c].empty())
      for (std::size_t k = first[c]; k < tally.size(); ++k) tally[k].under_skin = true;
    if (!placed_by_particles[c])
      for (std::size_t k = first[c]; k < tally.size(); ++k) tally[k].placed_by_gaps = true;
    for (double x : xs) {
      const auto k = static_cast<std::size_t>(std::upper_bound(bounds[c].begin(), bounds[c].end(), x) -
                                              bounds[c].begin());
      ClusterTally& t = tally[first[c] + k];
      ++t.surface_count;
      t.surface_x_sum += x;
      t.surface_x_min = std::min(t.surface_x_min, x);
      t.surface_x_max = std::max(t.surface_x_max, x);
    }
  }
  first[clusters.count] = tally.size();
  for (std::size_t p = 0; p < px.size(); ++p) {
    const auto label = clusters.label[p];
    if (label == DamageClusters::kNone) continue;
    const auto c = static_cast<std::size_t>(label);
    if (first[c] == first[c + 1]) continue;  // buried damage is not a crevasse
    const auto& b = bounds[c];
    const std::size_t k = static_cast<std::size_t>(std::upper_bound(b.begin(), b.end(), px[p]) - b.begin());
    ClusterTally& t = tally[first[c] + k];
    ++t.particle_count;
    t.z_min = std::min(t.z_min, pz[p]);
    // On the midpoint between two openings (the stem of a symmetric branch) it is both's.
    if (k > 0 && px[p] - b[k - 1] <= half_spacing)
      tally[first[c] + k - 1].z_min = std::min(tally[first[c] + k - 1].z_min, pz[p]);
    if (k < b.size() && b[k] - px[p] <= half_spacing)
      tally[first[c] + k + 1].z_min = std::min(tally[first[c] + k + 1].z_min, pz[p]);
  }

  std::vector<Candidate> candidates;
  for (const ClusterTally& t : tally) {
    if (t.surface_count == 0) continue;
    Candidate c;
    c.crevasse.x_m = t.surface_x_sum / static_cast<double>(t.surface_count);
    if (!window_has_length || !in_window(c.crevasse.x_m)) continue;
    c.left_m = t.surface_x_min - half_spacing;
    c.right_m = t.surface_x_max + half_spacing;
    // Local surface from the intact lips either side, so that neither an opening too wide to
    // be bridged nor a sloping or curved surface biases the depth.
    const double x_left_lip = c.left_m - r.lip_offset_m, x_right_lip = c.right_m + r.lip_offset_m;
    const double t_lip = (c.crevasse.x_m - x_left_lip) / (x_right_lip - x_left_lip);
    c.crevasse.surface_z_m =
        t.under_skin ? skin_top.height_at(c.crevasse.x_m)
                     : (1.0 - t_lip) * m.surface.height_at(x_left_lip) + t_lip * m.surface.height_at(x_right_lip);
    c.crevasse.bottom_z_m = t.z_min - half_spacing;
    // At most the ice's thickness (full depth): in the gate frame a layer damaged along the bed
    // may link to ice that started on the ramp, below the plateau's bed.
    c.crevasse.depth_m = std::clamp(c.crevasse.surface_z_m - c.crevasse.bottom_z_m, 0.0, r.ice_thickness_m);
    c.crevasse.particle_count = t.particle_count;
    c.crevasse.width_m = c.right_m - c.left_m;
    // An opened top is the mouth of a crack, deeper than it is wide; a gap wider than it is
    // deep is the surface sagging between two blocks beside a crack's lip, not a crack.
    if (t.placed_by_gaps && c.crevasse.depth_m < c.crevasse.width_m) continue;
    candidates.push_back(c);
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.crevasse.x_m < b.crevasse.x_m; });

  // Closer than the floor: one feature. It keeps the deeper one's position and depth, the
  // union of their widths; the spacing between them is dropped and counted.
  std::vector<Candidate> kept;
  const bool merge = r.spacing_rule == "merge";
  for (const Candidate& c : candidates) {
    if (merge && !kept.empty() && c.crevasse.x_m - kept.back().crevasse.x_m < r.resolution_floor_m) {
      Candidate& k = kept.back();
      const std::size_t particles = k.crevasse.particle_count + c.crevasse.particle_count;
      const std::size_t merged = k.crevasse.merged_count + c.crevasse.merged_count;
      const double left = std::min(k.left_m, c.left_m), right = std::max(k.right_m, c.right_m);
      if (c.crevasse.depth_m > k.crevasse.depth_m) k = c;
      k.left_m = left;
      k.right_m = right;
      k.crevasse.width_m = right - left;
      k.crevasse.particle_count = particles;
      k.crevasse.merged_count = merged;
      ++m.dropped_spacing_count;
    } else {
      kept.push_back(c);
    }
  }
  // Shallower than the depth floor (after merging, so a deep crevasse keeps a shallow
  // neighbour's width): not a crevasse at this resolution.
  std::erase_if(kept, [&](const Candidate& c) {
    const bool shallow = c.crevasse.depth_m < r.min_depth_m;
    m.shallow_count += shallow;
    return shallow;
  });
  for (std::size_t i = 0; i < kept.size(); ++i) {
    if (i + 1 < kept.size()) {
      const double s = kept[i + 1].crevasse.x_m - kept[i].crevasse.x_m;
      if (s < r.resolution_floor_m) {  // "drop" only: merging left no spacing below the floor
        ++m.dropped_spacing_count;
      } else {
        kept[i].crevasse.spacing_to_next_m = s;
        m.spacings_m.push_back(s);
      }
    }
    m.crevasses.push_back(kept[i].crevasse);
  }

  m.flags.no_crevasse = m.crevasses.empty();
  m.flags.has_spacing = !m.spacings_m.empty();
  const double inv_h = 1.0 / r.ice_thickness_m;
  if (m.flags.has_spacing) {
    m.spacing_m = quartiles(m.spacings_m);
    m.spacing_over_h = scaled(*m.spacing_m, inv_h);
  }
  if (!m.crevasses.empty()) {
    std::vector<double> depths;
    for (const Crevasse& c : m.crevasses) depths.push_back(c.depth_m);
    m.depth_m = quartiles(depths);
    m.depth_over_h = scaled(*m.depth_m, inv_h);
  }
  return m;
}

}  // namespace

}  // namespace crevasse::analysis
