#include "cli/accuracy_command.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include <nlohmann/json.hpp>

#include "analysis/regime_diagram.hpp"
#include "cli/cli_common.hpp"
#include "cli/csv_file.hpp"
#include "engine/error.hpp"
#include "engine/json_input.hpp"
#include "study/case_results.hpp"
#include "study/store.hpp"
#include "study/study_fit.hpp"

namespace crevasse {
namespace fs = std::filesystem;

namespace {

struct CostRow {
  const CaseRecord* c = nullptr;
  std::string label;  // the case index, prefixed with its database's stem for --add-cases
  double dx_m = 0.0, cfl = 0.0;
  std::optional<double> drive_m_s;  // piston speed V_x (absent when the scene has no drive)
  int ppc_axis = 0;
  std::optional<double> wall_s, peak_mb;
  std::optional<long long> steps, particle_steps;
};

std::string cell(const std::optional<double>& v) { return v ? short_number(*v) : "-"; }

std::string change_pct(const std::optional<double>& v, const std::optional<double>& ref) {
  if (!v || !ref || *ref == 0.0) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%+.1f%%", 100.0 * (*v / *ref - 1.0));
  return buf;
}

// The finished cases of one database with their numerics and cost; `prefix` labels them.
void read_cost_rows(const std::string& db_path, const std::string& prefix,
                    std::vector<CaseRecord>& cases, std::vector<CostRow>& rows) {
  Store store = Store::open_reader(db_path);
  cases = read_case_records(store);
  std::map<std::string, CostRow> by_id;
  Statement s(store.handle(),
              "SELECT case_id, scene_json, wall_s, peak_rss_bytes, steps, particle_steps "
              "FROM cases");
  while (s.step()) {
    CostRow r;
    const auto scene = parse_stored_json(s.text(1));
    if (!scene.is_object())
      throw InputError(db_path + ": case " + s.text(0) + ": its scene_json is not a valid scene");
    r.dx_m = scene.at("numerics").at("dx").get<double>();
    r.ppc_axis = scene.at("numerics").at("particles_per_cell_axis").get<int>();
    r.cfl = scene.at("numerics").at("cfl").get<double>();
    if (scene.contains("drive") && scene.at("drive").contains("speed"))
      r.drive_m_s = scene.at("drive").at("speed").get<double>();
    if (!s.is_null(2)) r.wall_s = s.real(2);
    if (!s.is_null(3)) r.peak_mb = s.real(3) / 1048576.0;
    if (!s.is_null(4)) r.steps = s.integer(4);
    if (!s.is_null(5)) r.particle_steps = s.integer(5);
    by_id[s.text(0)] = r;
  }
  for (const CaseRecord& c : cases) {
    if (c.status != "done") continue;
    CostRow r = by_id.at(c.case_id);
    r.c = &c;
    r.label = prefix + std::to_string(c.case_index);
    rows.push_back(r);
  }
}

}  // namespace

std::vector<fs::path> accuracy_report(const AccuracyCommandOptions& opt, std::string* table) {
  // Each database's records in their own vector, which the rows point into.
  std::vector<std::vector<CaseRecord>> cases(1 + opt.add_dbs.size());
  std::vector<CostRow> rows;
  read_cost_rows(opt.db_path, "", cases[0], rows);
  const std::size_t main_rows = rows.size();
  for (std::size_t i = 0; i < opt.add_dbs.size(); ++i) {
    const std::size_t before = rows.size();
    read_cost_rows(opt.add_dbs[i], fs::path(opt.add_dbs[i]).stem().string() + ":", cases[i + 1], rows);
    if (rows.size() == before)
      throw InputError("--add-cases: " + opt.add_dbs[i] + " has no finished case");
  }
  if (main_rows == 0) throw InputError(opt.db_path + ": no finished case; run the study first");
  {
    // A table of accuracy against cost needs runs that differ in their numerics.
    std::set<std::tuple<double, int, double, double>> numerics;
    for (const CostRow& r : rows) numerics.emplace(r.dx_m, r.ppc_axis, r.cfl, r.drive_m_s.value_or(0.0));
    if (numerics.size() < 2)
      throw InputError(opt.db_path + ": every finished case has the same numerics (dx, particles "
                       "per cell, CFL, drive speed); accuracy compares runs that differ in them "
                       "(e.g. studies/accuracy_flowing.json)");
  }
  // Coarsest grid first (the figure's colours and legend follow this order), then case order.
  std::stable_sort(rows.begin(), rows.end(),
                   [](const CostRow& a, const CostRow& b) { return a.dx_m > b.dx_m; });

  // The reference: the given case, else the finest run that has a spacing.
  const CostRow* ref = nullptr;
  if (opt.reference_index) {
    for (std::size_t i = 0; i < rows.size(); ++i)
      if (rows[i].label == std::to_string(*opt.reference_index)) ref = &rows[i];
    if (!ref)
      throw InputError("--reference: no finished case with index " +
                       std::to_string(*opt.reference_index) + " in " + opt.db_path);
  } else {
    for (const CostRow& r : rows)
      if (r.c->median(Quantity::spacing) &&
          (!ref || r.particle_steps.value_or(0) > ref->particle_steps.value_or(0)))
        ref = &r;
    if (!ref) throw InputError(opt.db_path + ": no finished case has a spacing to compare with");
  }

  create_output_directory("--out", opt.out_dir);
  const fs::path csv_path = fs::path(opt.out_dir) / "accuracy_cost.csv";
  const fs::path md_path = fs::path(opt.out_dir) / "accuracy_cost.md";
  CsvFile csv(csv_path, "--out");
  csv.row({"case", "dx_m", "particles_per_cell_axis", "cfl", "drive_speed_m_s", "steps", "particle_steps",
           "wall_s", "peak_rss_mib", "crevasses", "spacing_median_over_h", "depth_median_over_h",
           "spacing_change_vs_reference", "depth_change_vs_reference", "note"});
  std::ostringstream md;
  md << "Reference: case " << ref->c->case_index << " (dx = " << short_number(ref->dx_m)
     << " m, " << ref->ppc_axis << " particles per cell per axis, CFL " << short_number(ref->cfl)
     << ", V_x = " << cell(ref->drive_m_s)
     << " m/s). Changes are of the median against the reference's.\n\n"
     << "| case | dx [m] | ppc/axis | CFL | V_x [m/s] | steps | particle-steps | wall [s] | "
        "peak RSS [MiB] | crevasses | L_p/H_i | change | D_p/H_i | change | note |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  std::vector<analysis::RegimePoint> points;
  for (const CostRow& r : rows) {
    const CaseRecord& c = *r.c;
    const auto l = c.median(Quantity::spacing), d = c.median(Quantity::depth);
    const auto lr = ref->c->median(Quantity::spacing), dr = ref->c->median(Quantity::depth);
    std::string note = c.fragmented ? "fragmented" : "";
    if (!l) note += (note.empty() ? "" : "; ") + c.missing_reason(Quantity::spacing);
    if (&r == ref) note += (note.empty() ? "" : "; ") + std::string("reference");
    const std::string steps = r.steps ? std::to_string(*r.steps) : "-";
    const std::string psteps = r.particle_steps ? short_number(static_cast<double>(*r.particle_steps)) : "-";
    csv.row({r.label, short_number(r.dx_m), std::to_string(r.ppc_axis),
             short_number(r.cfl), cell(r.drive_m_s), steps, r.particle_steps ? std::to_string(*r.particle_steps) : "",
             cell(r.wall_s), cell(r.peak_mb), std::to_string(c.crevasse_count), cell(l), cell(d),
             change_pct(l, lr), change_pct(d, dr), note});
    md << "| " << r.label << " | " << short_number(r.dx_m) << " | " << r.ppc_axis << " | "
       << short_number(r.cfl) << " | " << cell(r.drive_m_s) << " | " << steps << " | " << psteps << " | " << cell(r.wall_s)
       << " | " << cell(r.peak_mb) << " | " << c.crevasse_count << " | " << cell(l) << " | "
       << change_pct(l, lr) << " | " << cell(d) << " | " << change_pct(d, dr) << " | " << note
       << " |\n";
    if (!r.wall_s || !(*r.wall_s > 0.0)) continue;
    analysis::RegimePoint p;
    p.pi = *r.wall_s;
    p.group = "dx = " + short_number(r.dx_m) + " m";
    if (r.drive_m_s != ref->drive_m_s) p.group += ", V_x = " + cell(r.drive_m_s) + " m/s";
    if (l) {
      p.y = *l;
      set_quartile_bar(p, c.quartiles(Quantity::spacing));
    } else {
      p.failed = true;
      p.missing_reason = c.fragmented ? "fragmented" : c.missing_reason(Quantity::spacing);
    }
    points.push_back(p);
  }
  analysis::RegimeDiagramOptions options;
  options.title = "accuracy against cost: median spacing of each run";
  options.x_label = "wall time [s] (one engine thread)";
  options.x_symbol = "t";
  csv.close();
  std::ofstream md_file(md_path);
  md_file << md.str();
  if (!md_file) throw InputError("--out: cannot write " + md_path.string());
  const analysis::Figure figure = analysis::regime_diagram(points, {}, options);
  const std::vector<fs::path> figure_files =
      write_png_and_svg(figure, fs::path(opt.out_dir) / "accuracy_cost");
  if (table) *table = md.str();
  return {csv_path, md_path, figure_files[0], figure_files[1]};
}

int accuracy_command(const AccuracyCommandOptions& opt) {
  check_output_directory("--out", opt.out_dir,
                         {"accuracy_cost.csv", "accuracy_cost.md", "accuracy_cost.png", "accuracy_cost.svg"});
  std::string table;
  const auto files = accuracy_report(opt, &table);
  std::printf("%s", table.c_str());
  std::printf("wrote %zu file(s) to %s\n", files.size(), opt.out_dir.c_str());
  return 0;
}

}  // namespace crevasse
