#include "study/study_compute.hpp"

#include <algorithm>
#include <map>

#include "study/store.hpp"

namespace crevasse {

std::vector<ComputeRow> study_compute(Store& store) {
  Statement s(store.handle(),
              "SELECT thickness_m, status, particle_steps, "
              "json_extract(run_json, '$.measured_from.kept_at_gate_mark_of_case_id') IS NOT NULL, "
              "CASE WHEN json_extract(run_json, '$.measured_from') IS NOT NULL "
              "THEN json_extract(run_json, '$.engine_wall_s') ELSE wall_s END "
              "FROM cases");
  std::map<double, ComputeRow> by_h;
  std::map<double, std::vector<double>> rates;
  while (s.step()) {
    const double h = s.real(0);
    ComputeRow& row = by_h[h];
    row.thickness_m = h;
    const std::string status = s.text(1);
    if (status != "done" && status != "failed") {
      ++row.pending;
    } else if (s.integer(3) != 0) {
      ++row.served;
    } else {
      ++row.run;
      const double pst = s.is_null(2) ? 0.0 : s.real(2);
      const double wall = s.is_null(4) ? 0.0 : s.real(4);
      row.particle_steps += pst;
      row.wall_s += wall;
      if (pst > 0 && wall > 0) rates[h].push_back(pst / wall);
    }
  }
  std::vector<ComputeRow> out;
  for (auto& [h, row] : by_h) {
    std::vector<double>& r = rates[h];
    if (!r.empty()) {
      std::sort(r.begin(), r.end());
      const std::size_t n = r.size();
      row.median_rate = n % 2 ? r[n / 2] : 0.5 * (r[n / 2 - 1] + r[n / 2]);
    }
    out.push_back(row);
  }
  return out;
}

ComputeRow compute_total(const std::vector<ComputeRow>& rows) {
  ComputeRow t;
  for (const ComputeRow& r : rows) {
    t.run += r.run;
    t.served += r.served;
    t.pending += r.pending;
    t.particle_steps += r.particle_steps;
    t.wall_s += r.wall_s;
  }
  return t;
}

}  // namespace crevasse
