// Nothing lost: a study is SIGKILLed at random moments again and again (≥ 20 kills),
// resumed each time with the same command; afterwards the database passes integrity_check, no
// finished case was lost, duplicated or rerun, and the contents equal an uninterrupted run.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>

#include <chrono>
#include <map>
#include <random>
#include <thread>

#include "../../study/study_test_support.hpp"

namespace crevasse {
namespace {

using namespace std::chrono_literals;

int run_to_end(const std::vector<std::string>& args) {
  std::string cmd = "'" CREVASSE_BINARY "'";
  for (const auto& a : args) cmd += " '" + a + "'";
  const int status = std::system((cmd + " 2> /dev/null").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(SlowKill, TwentyRandomKillsLoseNothing) {
  test::ScratchDir dir("kills");
  constexpr int kCases = 24;
  test::write_text(dir / "s.json", test::tiny_study(kCases, 3000, "kills").dump(2));
  auto args = [&](const std::string& db) {
    return std::vector<std::string>{"study",
                                    (dir / "s.json").string(),
                                    "--db",
                                    (dir / db).string(),
                                    "--jobs",
                                    "2",
                                    "--threads-per-case",
                                    "1",
                                    "--quiet"};
  };
  ASSERT_EQ(run_to_end(args("ref.db")), 0);

  std::mt19937 rng(12345);
  std::uniform_int_distribution<int> delay_ms(0, 400);
  std::map<std::string, std::string>
      finished;  // case_id → finished_at|session|result_hash, never to change
  int kills = 0;
  for (int round = 0; round < 200 && kills < 20; ++round) {
    const pid_t pid = test::spawn_crevasse(args("k.db"), "/dev/null");
    ASSERT_GT(pid, 0);
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms(rng)));
    ::kill(pid, SIGKILL);
    int status = 0;
    ::waitpid(pid, &status, 0);
    if (WIFSIGNALED(status)) ++kills;
    if (!std::filesystem::exists(dir / "k.db")) continue;
    ASSERT_EQ(test::pragma_integrity(dir / "k.db"), "ok") << "after kill " << kills;
    for (const auto& row :
         test::dump_rows(dir / "k.db",
                         "SELECT case_id, finished_at || '|' || session_id || '|' || "
                         "result_hash FROM cases WHERE status = 'done'")) {
      const auto bar = row.find('|');
      const std::string id = row.substr(0, bar), rest = row.substr(bar + 1);
      const auto [it, inserted] = finished.emplace(id, rest);
      EXPECT_EQ(it->second, rest) << "a finished case changed (rerun?) after kill " << kills;
    }
    if (!WIFSIGNALED(status)) break;  // the study completed before this kill
  }
  EXPECT_GE(kills, 20);
  ASSERT_EQ(run_to_end(args("k.db")), 0);
  EXPECT_EQ(test::pragma_integrity(dir / "k.db"), "ok");
  for (const auto& [id, rest] : finished) {
    const auto row =
        test::dump_rows(dir / "k.db",
                        "SELECT finished_at || '|' || session_id || '|' || result_hash "
                        "FROM cases WHERE case_id = '" +
                            id + "'");
    ASSERT_EQ(row.size(), 1u);
    EXPECT_EQ(row[0], rest) << "lost or rerun: " << id;
  }
  EXPECT_EQ(test::result_dump(dir / "k.db"), test::result_dump(dir / "ref.db"));
  std::printf("kills: %d, cases finished before the last resume: %zu of %d\n", kills,
              finished.size(), kCases);
}

}  // namespace
}  // namespace crevasse
