// The SQLite store: schema and WAL on creation, one writer at a time, a finished case written
// whole, refusals of files that are not study databases or hold another study.
#include <gtest/gtest.h>

#include "engine/error.hpp"
#include "study/store.hpp"
#include "study_test_support.hpp"

namespace crevasse {
namespace {

std::vector<const StudyCase*> all_cases(const Study& s) {
  std::vector<const StudyCase*> out;
  for (const auto& c : s.cases) out.push_back(&c);
  return out;
}

TEST(Store, CreatesTheSchemaInWalMode) {
  test::ScratchDir dir("store");
  const auto db = dir / "sub" / "s.db";
  {
    Store store = Store::open_writer(db);
    Statement s(store.handle(), "PRAGMA journal_mode");
    ASSERT_TRUE(s.step());
    EXPECT_EQ(s.text(0), "wal");
  }
  const auto tables =
      test::dump_rows(db, "SELECT name FROM sqlite_master WHERE type = 'table' ORDER BY name");
  EXPECT_EQ(tables,
            (std::vector<std::string>{"cases", "crevasses", "sessions", "study", "summaries"}));
  EXPECT_EQ(test::dump_rows(db, "PRAGMA user_version").at(0), std::to_string(kStoreSchemaVersion));
}

TEST(Store, OnlyOneWriterAtATime) {
  test::ScratchDir dir("store");
  Store first = Store::open_writer(dir / "s.db");
  try {
    Store second = Store::open_writer(dir / "s.db");
    FAIL() << "a second writer was allowed";
  } catch (const ResourceError& e) {
    EXPECT_NE(std::string(e.what()).find("another crevasse process is writing"), std::string::npos)
        << e.what();
  }
  // Readers are always welcome.
  Store reader = Store::open_reader(dir / "s.db");
  EXPECT_EQ(reader.counts().total(), 0);
}

TEST(Store, RefusesOtherFilesAndOtherStudies) {
  test::ScratchDir dir("store");
  EXPECT_THROW(Store::open_reader(dir / "missing.db"), InputError);
  test::write_text(dir / "text.db",
                   "this is not a database, just some text that is long enough to matter....");
  EXPECT_THROW(Store::open_reader(dir / "text.db"), InputError);
  {
    sqlite3* other = nullptr;
    sqlite3_open((dir / "other.db").c_str(), &other);
    sqlite3_exec(other, "CREATE TABLE t (x)", nullptr, nullptr, nullptr);
    sqlite3_close(other);
  }
  EXPECT_THROW(Store::open_writer(dir / "other.db"), InputError);

  Store store = Store::open_writer(dir / "s.db");
  store.init_study(test::parse(test::tiny_study(2)));
  store.init_study(test::parse(test::tiny_study(2)));  // the same study again is fine
  try {
    store.init_study(test::parse(test::tiny_study(3)));
    FAIL() << "another study was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("use another --db"), std::string::npos) << e.what();
  }
}

// A case with c/(ρ_i g) on the resolution floor itself (Π = 3 dx/H_i; round-off puts the length a
// hair under 30 m) is resolved, whether the flag comes from the row's column, from the rule a
// version-1 file is read with, or from a column an older rule wrote.
TEST(Store, TheResolutionFloorHoldsInEveryWayTheFlagIsRead) {
  test::ScratchDir dir("store");
  auto j = test::tiny_study(1);
  j["fixed"]["thickness"] = 200.0;
  j["sweep"] = {{"cohesion_ratio", {0.1, 0.15, 0.2}}};  // below, on and above 30 m at dx = 10 m
  const Study study = test::parse(j);
  const auto db = dir / "s.db";
  const std::string flags = "SELECT group_concat(f, ',') FROM (SELECT under_resolved AS f FROM cases ORDER BY case_index)";
  {
    Store store = Store::open_writer(db);
    store.init_study(study);
    store.add_cases(all_cases(study));
  }
  EXPECT_EQ(test::dump_rows(db, flags).at(0), "1,0,0");

  // A column an older rule wrote is brought up to the current rule when a writer opens the file.
  { Store store = Store::open_writer(db); store.exec("UPDATE cases SET under_resolved = 1"); }
  { Store store = Store::open_writer(db); }
  EXPECT_EQ(test::dump_rows(db, flags).at(0), "1,0,0");

  // A version-1 file (no column): read with the rule, then upgraded by a writer.
  {
    Store store = Store::open_writer(db);
    store.exec("DROP INDEX IF EXISTS cases_by_status");
    store.exec("ALTER TABLE cases DROP COLUMN under_resolved");
    store.exec("PRAGMA user_version = 1");
  }
  {
    Store reader = Store::open_reader(db);
    ASSERT_EQ(reader.schema_version(), 1);
    Statement s(reader.handle(),
                "SELECT " + reader.under_resolved_column() + " FROM cases ORDER BY case_index");
    std::string got;
    while (s.step()) got += (got.empty() ? "" : ",") + std::to_string(s.integer(0));
    EXPECT_EQ(got, "1,0,0");
  }
  { Store store = Store::open_writer(db); }
  EXPECT_EQ(test::dump_rows(db, flags).at(0), "1,0,0");
}

TEST(Store, AFinishedCaseIsStoredWhole) {
  test::ScratchDir dir("store");
  const Study study = test::parse(test::tiny_study(3));
  Store store = Store::open_writer(dir / "s.db");
  store.init_study(study);
  store.add_cases(all_cases(study));
  store.add_cases(all_cases(study));  // idempotent
  EXPECT_EQ(store.counts().pending, 3);

  const StudyCase& c = study.cases[2];
  store.mark_running(c.case_id, "session", utc_now_iso8601(), 1);
  EXPECT_EQ(store.counts().running, 1);
  CaseResult r;
  r.case_id = c.case_id;
  r.status = "done";
  r.stop_reason = "fake";
  r.session_id = "session";
  r.measurement = test::fake_outcome(c).measurement;
  r.result_json = {{"x", 1}};
  store.record_result(r);
  EXPECT_EQ(store.counts().done, 1);
  EXPECT_EQ(test::dump_rows(dir / "s.db", "SELECT count(*) FROM crevasses").at(0), "3");
  EXPECT_EQ(
      test::dump_rows(dir / "s.db", "SELECT crevasse_count, spacing_median_m FROM summaries").at(0),
      "3|50.0");
  EXPECT_EQ(test::dump_rows(dir / "s.db", "SELECT attempts, status FROM cases WHERE case_id = '" +
                                              c.case_id + "'")
                .at(0),
            "1|done");

  // Stored again (a retried case): replaced, not duplicated.
  r.measurement->crevasses.resize(1);
  r.measurement->spacings_m.clear();
  store.record_result(r);
  EXPECT_EQ(test::dump_rows(dir / "s.db", "SELECT count(*) FROM crevasses").at(0), "1");
  EXPECT_EQ(test::dump_rows(dir / "s.db", "SELECT count(*) FROM summaries").at(0), "1");

  // A killed run leaves 'running' rows; they go back to pending.
  store.mark_running(study.cases[0].case_id, "session", utc_now_iso8601(), 1);
  EXPECT_EQ(store.reset_running(), 1);
  EXPECT_EQ(store.counts().pending, 2);
  EXPECT_EQ(test::pragma_integrity(dir / "s.db"), "ok");
}

}  // namespace
}  // namespace crevasse
