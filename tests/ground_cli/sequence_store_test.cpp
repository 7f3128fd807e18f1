// Sequence numbers of a sender: strictly increasing across processes (the state file), never
// handed out twice under concurrency (the lock), and --seq style floors respected.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <thread>
#include <vector>

#include "ground/cli/sequence_store.hpp"
#include "test_util.hpp"

namespace rocksteady::ground::cli {
namespace {

TEST(SequenceStore, NumbersIncreaseAcrossInstancesFromOne) {
  test::TempDir dir;
  const std::string path = sequence_file(dir.str() + "/state", 1);
  EXPECT_EQ(SequenceStore(path).last(), 0);
  EXPECT_EQ(SequenceStore(path).next(), 1);
  EXPECT_EQ(SequenceStore(path).next(), 2);
  SequenceStore s(path);
  EXPECT_EQ(s.next(), 3);
  EXPECT_EQ(s.last(), 3);
  // Another sender has its own numbers.
  EXPECT_EQ(SequenceStore(sequence_file(dir.str() + "/state", 2)).next(), 1);
}

TEST(SequenceStore, FloorRaisesTheNextNumberAndIsRemembered) {
  test::TempDir dir;
  SequenceStore s(dir.file("seq"));
  EXPECT_EQ(s.next(100), 100);
  EXPECT_EQ(s.next(), 101);
  EXPECT_EQ(s.next(50), 102);  // a floor below the last number never goes back
}

TEST(SequenceStore, ConcurrentSendersNeverShareANumber) {
  test::TempDir dir;
  const std::string path = dir.file("seq");
  constexpr int kThreads = 4;
  constexpr int kEach = 50;
  std::vector<std::vector<std::int64_t>> got(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      for (int i = 0; i < kEach; ++i)
        got[static_cast<std::size_t>(t)].push_back(SequenceStore(path).next());
    });
  }
  for (std::thread& th : threads) th.join();
  std::set<std::int64_t> all;
  for (const auto& g : got) {
    EXPECT_TRUE(std::is_sorted(g.begin(), g.end()));  // each sender sees its numbers increase
    all.insert(g.begin(), g.end());
  }
  EXPECT_EQ(all.size(), static_cast<std::size_t>(kThreads * kEach));
  EXPECT_EQ(*all.begin(), 1);
  EXPECT_EQ(*all.rbegin(), kThreads * kEach);
}

TEST(SequenceStore, UnusableStatePathIsAnErrorNamingThePath) {
  test::TempDir dir;
  const std::string blocker = dir.file("not-a-dir");
  { std::ofstream(blocker) << "x"; }
  try {
    SequenceStore(blocker + "/seq").next();
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(blocker), std::string::npos) << e.what();
  }
}

TEST(SequenceStore, DefaultDirectoryFollowsXdgStateHome) {
  const char* old_xdg = std::getenv("XDG_STATE_HOME");
  const std::string saved = old_xdg != nullptr ? old_xdg : "";
  setenv("XDG_STATE_HOME", "/var/tmp/xdg-state", 1);
  EXPECT_EQ(default_state_dir(), "/var/tmp/xdg-state/rocksteady");
  unsetenv("XDG_STATE_HOME");
  const char* home = std::getenv("HOME");
  if (home != nullptr && home[0] != '\0') {
    EXPECT_EQ(default_state_dir(), std::string(home) + "/.local/state/rocksteady");
  }
  if (old_xdg != nullptr) setenv("XDG_STATE_HOME", saved.c_str(), 1);
}

}  // namespace
}  // namespace rocksteady::ground::cli
