#include "core/atomic_file.h"

#include <fstream>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/support/gl_test.h"

namespace core {
namespace {
namespace fs = std::filesystem;

std::string Slurp(const fs::path& p) {
  std::ifstream in(p);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

TEST(AtomicWrite, ReplacesOnlyOnSuccess) {
  const auto dir = test_support::TestOutputDir();
  const auto file = dir / "f.txt";
  AtomicWriteStream(file, [](std::ostream& out) { out << "first"; });
  EXPECT_EQ(Slurp(file), "first");
  EXPECT_THROW(AtomicWriteStream(file,
                                 [](std::ostream& out) {
                                   out << "partial";
                                   throw InputError("boom");
                                 }),
               InputError);
  EXPECT_EQ(Slurp(file), "first");
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1) << "a temporary file was left behind";
}

TEST(StagedDirectory, CommitMovesIntoPlaceAndAbortRemoves) {
  const auto root = test_support::TestOutputDir();
  const auto target = root / "out";
  {
    StagedDirectory staged(target);
    std::ofstream(staged.path() / "a.txt") << "a";
    EXPECT_FALSE(fs::exists(target));
    staged.Commit();
  }
  EXPECT_EQ(Slurp(target / "a.txt"), "a");
  {
    StagedDirectory staged(target);
    std::ofstream(staged.path() / "b.txt") << "b";
    // no Commit: simulates a failure half way
  }
  EXPECT_TRUE(fs::exists(target / "a.txt"));
  EXPECT_FALSE(fs::exists(target / "b.txt"));
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(root)) ++entries;
  EXPECT_EQ(entries, 1) << "staging directory left behind";
  {
    StagedDirectory staged(target);
    std::ofstream(staged.path() / "c.txt") << "c";
    staged.Commit();
  }
  EXPECT_FALSE(fs::exists(target / "a.txt"));
  EXPECT_EQ(Slurp(target / "c.txt"), "c");
}

TEST(StagedDirectory, RefusesAFileInTheWay) {
  const auto root = test_support::TestOutputDir();
  std::ofstream(root / "file") << "x";
  EXPECT_THROW(StagedDirectory(root / "file"), InputError);
}

}  // namespace
}  // namespace core
