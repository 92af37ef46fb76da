#include "cli/export_command.hpp"

#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "cli/cli_common.hpp"
#include "cli/csv_file.hpp"
#include "engine/error.hpp"
#include "engine/json_input.hpp"
#include "study/fits_table.hpp"
#include "study/store.hpp"

namespace crevasse {
namespace fs = std::filesystem;

namespace {

std::string json_scalar(const nlohmann::json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_null()) return "";
  return v.dump();
}

// Leaves of a JSON object as "prefix.a.b" → value; arrays are kept as JSON text.
void flatten(const nlohmann::json& j, const std::string& prefix,
             std::map<std::string, std::string>& out) {
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it)
      flatten(it.value(), prefix + "." + it.key(), out);
  } else {
    out[prefix] = json_scalar(j);
  }
}

void export_table(sqlite3* db, const std::string& table, const fs::path& path) {
  Statement s(db, "SELECT * FROM " + table + " ORDER BY rowid");
  CsvFile f(path);
  std::vector<std::string> header;
  for (int c = 0; c < s.columns(); ++c) header.push_back(s.column_name(c));
  f.row(header);
  while (s.step()) {
    std::vector<std::string> row;
    for (int c = 0; c < s.columns(); ++c) row.push_back(s.is_null(c) ? "" : s.text(c));
    f.row(row);
  }
  f.close();
}

// cases.csv: the scalar columns, then axis.* and scene.* columns; the JSON columns stay in the
// database.
void export_cases(sqlite3* db, const fs::path& path) {
  const std::set<std::string> blobs = {"axes_json", "scene_json", "run_json", "result_json"};
  Statement s(db, "SELECT * FROM cases ORDER BY case_index");
  std::vector<int> scalar_cols;
  int axes_col = -1, scene_col = -1;
  std::vector<std::string> header;
  for (int c = 0; c < s.columns(); ++c) {
    const std::string name = s.column_name(c);
    if (name == "axes_json") axes_col = c;
    if (name == "scene_json") scene_col = c;
    if (blobs.count(name)) continue;
    scalar_cols.push_back(c);
    header.push_back(name);
  }
  std::vector<std::vector<std::string>> rows;
  std::vector<std::map<std::string, std::string>> flat;
  std::set<std::string> flat_keys_set;
  std::vector<std::string> flat_keys;  // first-seen order
  while (s.step()) {
    std::vector<std::string> row;
    for (int c : scalar_cols) row.push_back(s.is_null(c) ? "" : s.text(c));
    rows.push_back(std::move(row));
    std::map<std::string, std::string> f;
    const auto axes = parse_stored_json(s.text(axes_col));
    if (axes.is_object())
      for (auto it = axes.begin(); it != axes.end(); ++it)
        f["axis." + it.key()] = json_scalar(it.value());
    const auto scene = parse_stored_json(s.text(scene_col));
    if (!scene.is_discarded()) flatten(scene, "scene", f);
    for (const auto& [k, v] : f)
      if (flat_keys_set.insert(k).second) flat_keys.push_back(k);
    flat.push_back(std::move(f));
  }
  CsvFile out(path);
  std::vector<std::string> full_header = header;
  full_header.insert(full_header.end(), flat_keys.begin(), flat_keys.end());
  out.row(full_header);
  for (std::size_t r = 0; r < rows.size(); ++r) {
    std::vector<std::string> row = rows[r];
    for (const auto& k : flat_keys) {
      const auto it = flat[r].find(k);
      row.push_back(it == flat[r].end() ? "" : it->second);
    }
    out.row(row);
  }
  out.close();
}

}  // namespace

std::vector<fs::path> export_csv(const fs::path& db_path, const fs::path& dir) {
  Store store = Store::open_reader(db_path);
  check_output_directory("--csv", dir, {"study.csv", "sessions.csv", "crevasses.csv", "summaries.csv",
                                        "cases.csv", "fits.csv"});
  create_output_directory("--csv", dir);
  std::vector<fs::path> files;
  // One read transaction, so that the files agree with each other while a study is running.
  store.exec("BEGIN");
  for (const char* table : {"study", "sessions", "crevasses", "summaries"}) {
    files.push_back(dir / (std::string(table) + ".csv"));
    export_table(store.handle(), table, files.back());
  }
  files.push_back(dir / "cases.csv");
  export_cases(store.handle(), files.back());
  if (has_fits_table(store)) {
    files.push_back(dir / "fits.csv");
    export_table(store.handle(), "fits", files.back());
  }
  store.exec("COMMIT");
  return files;
}

int export_command(const ExportCommandOptions& opt) {
  const auto files = export_csv(opt.db_path, opt.csv_dir);
  for (const auto& f : files) std::printf("%s\n", f.c_str());
  return 0;
}

}  // namespace crevasse
