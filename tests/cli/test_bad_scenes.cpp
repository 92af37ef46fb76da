// Bad input on the command line. Every file of the malformed-scene corpus
// tests/inputs/bad_scenes/ makes `crevasse run` exit with code 2 and exactly one line on stderr
// naming the field (expected.json maps each file to it), and writes no output. A bad study run
// against an existing database leaves it byte-for-byte unchanged.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "../study/study_test_support.hpp"

namespace crevasse {
namespace {

namespace fs = std::filesystem;

const fs::path kCorpus = fs::path(CREVASSE_SOURCE_DIR) / "tests" / "inputs" / "bad_scenes";

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

// File name → the field its error message must name.
std::map<std::string, std::string> expected_fields() {
  const auto j = nlohmann::json::parse(slurp(kCorpus / "expected.json"));
  return j.get<std::map<std::string, std::string>>();
}

std::vector<std::string> corpus_files() {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(kCorpus))
    if (e.path().filename() != "expected.json") names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

struct Outcome {
  int code = -1;
  std::string err;
};

// Runs the crevasse binary with `args`; stdout is discarded, stderr returned.
Outcome run_crevasse(const std::vector<std::string>& args, const fs::path& scratch) {
  const fs::path err = scratch / "stderr.txt";
  const pid_t pid = test::spawn_crevasse(args, err.string());
  Outcome o;
  if (pid <= 0) return o;
  int status = 0;
  ::waitpid(pid, &status, 0);
  o.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  o.err = slurp(err);
  return o;
}

void expect_one_line_naming(const Outcome& o, const std::string& field, const std::string& what) {
  EXPECT_EQ(o.code, 2) << what << ": " << o.err;
  EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << what << ": one line:\n" << o.err;
  EXPECT_EQ(o.err.rfind("crevasse: error: ", 0), 0u) << what << ": " << o.err;
  EXPECT_NE(o.err.find(field), std::string::npos)
      << what << ": does not name " << field << ": " << o.err;
}

TEST(BadScenes, CorpusHasThirtyOrMoreFilesEachWithItsField) {
  const auto expected = expected_fields();
  const auto files = corpus_files();
  EXPECT_GE(files.size(), 30u);
  for (const auto& f : files)
    EXPECT_TRUE(expected.count(f)) << f << " has no entry in expected.json";
  for (const auto& [f, field] : expected) {
    EXPECT_TRUE(fs::exists(kCorpus / f)) << f << " listed in expected.json but missing";
    EXPECT_FALSE(field.empty()) << f;
  }
}

class BadScene : public ::testing::TestWithParam<std::string> {};

TEST_P(BadScene, ExitsWithCode2OneLineNamingTheFieldAndWritesNothing) {
  const std::string file = GetParam();
  const std::string field = expected_fields().at(file);
  test::ScratchDir dir("bad_scene");
  const fs::path out = dir / "out";
  const Outcome o =
      run_crevasse({"run", (kCorpus / file).string(), "--out", out.string()}, dir.path());
  expect_one_line_naming(o, field, file);
  EXPECT_FALSE(fs::exists(out)) << file << ": a refused scene created its output directory";
}

std::string test_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string n = fs::path(info.param).stem().string();
  for (char& c : n)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return n;
}

INSTANTIATE_TEST_SUITE_P(Corpus, BadScene, ::testing::ValuesIn(corpus_files()), test_name);

// Each defect gets its own message, not one generic refusal.
TEST(BadScenes, EveryFileGetsItsOwnMessage) {
  test::ScratchDir dir("bad_scene");
  std::map<std::string, std::string> seen;  // message → file
  for (const auto& file : corpus_files()) {
    const Outcome o = run_crevasse(
        {"run", (kCorpus / file).string(), "--out", (dir / "out").string()}, dir.path());
    const auto [it, inserted] = seen.emplace(o.err, file);
    EXPECT_TRUE(inserted) << file << " and " << it->second << " give the same message: " << o.err;
  }
}

// Every file of a directory, by name: its bytes (what "unchanged" means for a database, its
// WAL and shared-memory files, and any journal a writer would leave).
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().rfind("keep.db", 0) == 0)
      files[e.path().filename().string()] = slurp(e.path());
  return files;
}

TEST(BadStudies, ExistingDatabaseIsByteForByteUnchanged) {
  test::ScratchDir dir("bad_study_db");
  test::write_text(dir / "good.json", test::tiny_study(2, 20, "keep").dump(2));
  const fs::path db = dir / "keep.db";
  const Outcome first = run_crevasse(
      {"study", (dir / "good.json").string(), "--db", db.string(), "--quiet"}, dir.path());
  ASSERT_EQ(first.code, 0) << first.err;
  const auto before = snapshot(dir.path());
  ASSERT_TRUE(before.count("keep.db"));

  // The scene corpus as base scenes of a study with the same name as the stored one ...
  std::vector<std::pair<std::string, std::string>> studies;  // text, field
  for (const auto& [file, field] : expected_fields()) {
    nlohmann::json s = {{"name", "keep"}, {"base_scene", (kCorpus / file).string()}};
    studies.emplace_back(s.dump(), field);
  }
  // ... and study-level defects the loader tests (tests/study/test_study_file.cpp) do not cover: inputs
  // that reached the store or escaped as other exceptions before the fuzzer found them.
  const std::string scene = test::tiny_scene(20).dump();
  const std::vector<std::pair<std::string, std::string>> more = {
      {R"({"name": "keep", "base_scene": ")" + dir.path().string() + R"("})", "base_scene"},
      {R"({"name": "keep", "base_scene": "/dev/zero"})", "base_scene"},
      {R"({"name": "keep", "base_scene": )" + scene + R"(, "sweep": {"cohesion_ratio": [1e400]}})",
       "not valid JSON"},
      {R"({"name": "keep", "base_scene": )" + scene +
           R"(, "fixed": {"/velocity_boxes/99999999999/min": [0, 0]}})",
       "fixed./velocity_boxes/99999999999/min"},
      {R"({"name": "keep", "base_scene": )" + scene +
           R"(, "fixed": {"/effects/first": "gravity"}})",
       "fixed./effects/first"},
      {R"({"name": "keep", "base_scene": {"ice": 5, "run": {"max_steps": 5}}, "fixed": {"thickness": 40}})",
       "ice"},
      {R"({"name": "keep", "base_scene": )" + scene + R"(, "fixed": [1, 2]})", "fixed"},
      {R"({"name": "keep", "base_scene": )" + scene + R"(, "replicas": {"count": 2.5}})",
       "replicas.count"},
  };
  studies.insert(studies.end(), more.begin(), more.end());
  for (const auto& [text, field] : studies) {
    test::write_text(dir / "bad.json", text);
    const Outcome o =
        run_crevasse({"study", (dir / "bad.json").string(), "--db", db.string()}, dir.path());
    expect_one_line_naming(o, field, text.substr(0, 200));
    EXPECT_EQ(snapshot(dir.path()), before)
        << "the database changed after: " << text.substr(0, 200);
  }
  // A good study file with a bad command-line option is refused the same way.
  const Outcome shard = run_crevasse(
      {"study", (dir / "good.json").string(), "--db", db.string(), "--shard", "3/2"}, dir.path());
  EXPECT_EQ(shard.code, 2) << shard.err;
  EXPECT_EQ(snapshot(dir.path()), before);
}

}  // namespace
}  // namespace crevasse
