// docs/scene_format.md is the reference of the scene's fields; the field table in
// engine/scene.cpp reads, writes and checks them. This holds the two to each other: every field
// of the table has its row in the docs' section, with the same type, unit, default and range.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "engine/scene.hpp"

namespace crevasse {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(' '), e = s.find_last_not_of(' ');
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

// The cells of a markdown table row ("| a | b |" → {"a", "b"}); escaped bars stay in the cell.
std::vector<std::string> cells(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  for (std::size_t i = 1; i < line.size(); ++i) {
    if (line[i] == '|' && line[i - 1] != '\\') {
      out.push_back(trim(cell));
      cell.clear();
    } else {
      cell += line[i];
    }
  }
  return out;
}

// "section.key" → the row's cells, from the docs' "## ice", "### ice.softening", ... tables.
std::map<std::string, std::vector<std::string>> docs_rows() {
  std::ifstream in(std::string(CREVASSE_SOURCE_DIR) + "/docs/scene_format.md");
  EXPECT_TRUE(in.good());
  std::map<std::string, std::vector<std::string>> rows;
  std::string line, section;
  while (std::getline(in, line)) {
    if (line.rfind("## ", 0) == 0 || line.rfind("### ", 0) == 0) {
      section = trim(line.substr(line.find(' ') + 1));
    } else if (line.rfind("| `", 0) == 0) {
      const auto c = cells(line);
      if (c.size() == 5) rows[section + "." + c[0].substr(1, c[0].size() - 2)] = c;
    }
  }
  return rows;
}

TEST(SceneFields, DocsTableMatchesTheFieldTable) {
  const auto rows = docs_rows();
  const auto fields = scene_field_docs();
  ASSERT_GT(fields.size(), 40u);
  for (const auto& f : fields) {
    SCOPED_TRACE(f.path);
    const auto it = rows.find(f.path);
    ASSERT_NE(it, rows.end()) << "no row in docs/scene_format.md";
    const auto& c = it->second;  // key, type, unit, default, allowed
    EXPECT_EQ(c[1], f.type);
    EXPECT_EQ(c[2], f.unit);
    EXPECT_EQ(c[3].rfind(f.default_value, 0), 0u) << "default cell '" << c[3] << "', table: " << f.default_value;
    if (!f.range.empty()) {
      EXPECT_NE(c[4].find(f.range), std::string::npos) << "allowed '" << c[4] << "', table: " << f.range;
    }
  }
}

}  // namespace
}  // namespace crevasse
