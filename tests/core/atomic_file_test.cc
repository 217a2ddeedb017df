#include "core/atomic_file.h"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <set>
#include <thread>

#include "core/error.h"
#include "tests/support/gl_test.h"

namespace core {
namespace {
namespace fs = std::filesystem;

std::string Slurp(const fs::path& p) {
  std::ifstream in(p);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::set<std::string> Entries(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    names.insert(fs::relative(e.path(), dir).generic_string());
  return names;
}

// A user's folder: two documents and a subfolder.
fs::path UserFolder(const fs::path& root) {
  const fs::path docs = root / "Documents";
  fs::create_directories(docs / "taxes");
  std::ofstream(docs / "letter.txt") << "dear";
  std::ofstream(docs / "taxes" / "2025.pdf") << "%PDF";
  return docs;
}

void ExpectUserFolderIntact(const fs::path& docs) {
  EXPECT_EQ(Slurp(docs / "letter.txt"), "dear");
  EXPECT_EQ(Slurp(docs / "taxes" / "2025.pdf"), "%PDF");
  EXPECT_EQ(Entries(docs), (std::set<std::string>{"letter.txt", "taxes", "taxes/2025.pdf"}));
}

// The message of the InputError `f` throws ("" if none).
template <typename F>
std::string ErrorOf(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(AtomicWrite, ReplacesOnlyOnSuccess) {
  const auto dir = test_support::TestOutputDir();
  const auto file = dir / "f.txt";
  AtomicWriteStream(file, [](std::ostream& out) { out << "first"; });
  EXPECT_EQ(Slurp(file), "first");
  EXPECT_THROW(AtomicWriteStream(
                   file,
                   [](std::ostream& out) {
                     out << "partial";
                     throw InputError("boom");
                   },
                   ExistingFile::kReplace),
               InputError);
  EXPECT_EQ(Slurp(file), "first");
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1) << "a temporary file was left behind";
}

TEST(AtomicWrite, OnlyAFileIbrWroteIsReplaced) {
  const auto dir = test_support::TestOutputDir();
  // Text formats carry the mark in their header; a mark elsewhere is not one.
  std::ofstream(dir / "ours.ply") << "ply\nformat ascii 1.0\ncomment " << kFileMark
                                  << "\nend_header\n";
  std::ofstream(dir / "late.ply") << "ply\nend_header\ncomment " << kFileMark << "\n";
  std::ofstream(dir / "ours.obj") << "# " << kFileMark << "\nv 0 0 0\n";
  std::ofstream(dir / "theirs.obj") << "# Blender\nv 0 0 0\n";
  std::ofstream(dir / "notes.csv") << kFileMark << "\n";
  EXPECT_TRUE(IsIbrOutputFile(dir / "ours.ply"));
  EXPECT_FALSE(IsIbrOutputFile(dir / "late.ply"));
  EXPECT_TRUE(IsIbrOutputFile(dir / "ours.obj"));
  EXPECT_FALSE(IsIbrOutputFile(dir / "theirs.obj"));
  EXPECT_FALSE(IsIbrOutputFile(dir / "notes.csv"));
  EXPECT_FALSE(IsIbrOutputFile(dir / "absent.ply"));
  EXPECT_FALSE(IsIbrOutputFile(dir));
  // A folder marker lists other files of ibr's, and is one itself.
  std::ofstream(dir / kOutputMarker) << "ibr output: ibr report\nnotes.csv\n";
  EXPECT_TRUE(IsIbrOutputFile(dir / "notes.csv"));
  EXPECT_TRUE(IsIbrOutputFile(dir / kOutputMarker));
  std::ofstream(dir / kOutputMarker) << "my own notes\nnotes.csv\n";
  EXPECT_FALSE(IsIbrOutputFile(dir / kOutputMarker));
  EXPECT_FALSE(IsIbrOutputFile(dir / "notes.csv"));

  std::ofstream(dir / "theirs.txt") << "precious";
  EXPECT_NE(ErrorOf([&] {
              AtomicWriteStream(dir / "theirs.txt", [](std::ostream& out) { out << "x"; });
            }).find("ibr did not write it"),
            std::string::npos);
  EXPECT_EQ(Slurp(dir / "theirs.txt"), "precious");
  SetOverwriteFiles(true);
  AtomicWriteStream(dir / "theirs.txt", [](std::ostream& out) { out << "x"; });
  SetOverwriteFiles(false);
  EXPECT_EQ(Slurp(dir / "theirs.txt"), "x");
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

TEST(StagedDirectory, RefusesAFolderIbrDidNotWriteAndLeavesItIntact) {
  const auto root = test_support::TestOutputDir();
  const fs::path docs = UserFolder(root);
  const std::string message = ErrorOf([&] { StagedDirectory staged(docs); });
  EXPECT_NE(message.find("is not an earlier ibr output"), std::string::npos) << message;
  EXPECT_NE(message.find(docs.string()), std::string::npos) << message;
  ExpectUserFolderIntact(docs);
  EXPECT_EQ(Entries(root), (std::set<std::string>{"Documents", "Documents/letter.txt",
                                                  "Documents/taxes", "Documents/taxes/2025.pdf"}));
}

TEST(StagedDirectory, MarkerListsFilesAndAUserFileAddedLaterBlocksReplacement) {
  const auto root = test_support::TestOutputDir();
  const fs::path out = root / "out";
  SetOutputDescription("ibr test --out out");
  {
    StagedDirectory staged(out);
    fs::create_directories(staged.path() / "depth");
    std::ofstream(staged.path() / "depth" / "a.exr") << "a";
    std::ofstream(staged.path() / "dataset.json") << "{}";
    staged.Commit();
  }
  EXPECT_EQ(Slurp(out / kOutputMarker),
            "ibr output: ibr test --out out\ndataset.json\ndepth/a.exr\n");
  {  // an earlier output is replaced
    StagedDirectory staged(out);
    std::ofstream(staged.path() / "dataset.json") << "{\"v\": 2}";
    staged.Commit();
  }
  EXPECT_EQ(Slurp(out / "dataset.json"), "{\"v\": 2}");
  EXPECT_FALSE(fs::exists(out / "depth"));
  // The user keeps notes in it: now it is theirs too, and never replaced.
  std::ofstream(out / "notes.txt") << "mine";
  const std::string message = ErrorOf([&] { StagedDirectory staged(out); });
  EXPECT_NE(message.find("holds 'notes.txt', which ibr did not write"), std::string::npos)
      << message;
  // ...also when the note appears while the output is being written.
  fs::remove(out / "notes.txt");
  {
    StagedDirectory staged(out);
    std::ofstream(out / "notes.txt") << "mine";
    EXPECT_THROW(staged.Commit(), InputError);
  }
  EXPECT_EQ(Slurp(out / "notes.txt"), "mine");
  EXPECT_EQ(Entries(root).size(), Entries(out).size() + 1) << "staging folder left behind";
}

TEST(StagedDirectory, EmptyFolderIsReplacedAndSymlinkIsRefused) {
  const auto root = test_support::TestOutputDir();
  fs::create_directories(root / "empty");
  {
    StagedDirectory staged(root / "empty");
    std::ofstream(staged.path() / "x") << "x";
    staged.Commit();
  }
  EXPECT_EQ(Slurp(root / "empty" / "x"), "x");
  const fs::path docs = UserFolder(root);
  fs::create_directory_symlink(fs::absolute(docs), root / "link");
  EXPECT_THROW(StagedDirectory(root / "link"), InputError);
  ExpectUserFolderIntact(docs);
}

TEST(StagedDirectory, OutputNeverOverlapsAnInput) {
  const auto root = test_support::TestOutputDir();
  const fs::path input = root / "in";
  {
    StagedDirectory staged(
        input);  // an earlier ibr output: replaceable, unless it is this run's input
    std::ofstream(staged.path() / "dataset.json") << "{}";
    staged.Commit();
  }
  // Absolute targets: a relative one would resolve against the link's folder
  // (TestOutputDir is relative without IBR_TEST_OUTPUT).
  fs::create_directory_symlink(fs::absolute(input), root / "alias");
  NoteInputPath(input);
  for (const fs::path& out : {input, root / "alias", root / "in" / ".." / "in", input / "renders",
                              root / "alias" / "sub" / "deeper", fs::path(root)}) {
    const std::string message = ErrorOf([&] { StagedDirectory staged(out); });
    EXPECT_FALSE(message.empty()) << out;
    EXPECT_NE(message.find("input"), std::string::npos) << message;
  }
  EXPECT_THROW(AtomicWriteStream(input / "dataset.json", [](std::ostream& o) { o << "x"; }),
               InputError);
  EXPECT_EQ(Slurp(input / "dataset.json"), "{}");
  // A sibling is fine.
  {
    StagedDirectory staged(root / "in2");
    staged.Commit();
  }
  ClearInputPaths();
  EXPECT_TRUE(fs::exists(root / "in2" / kOutputMarker));
}

TEST(StagedDirectory, StaleStagingOfDeadProcessesIsRemovedLiveOnesKept) {
  const auto root = test_support::TestOutputDir();
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ASSERT_GT(child, 0);
  ::waitpid(child, nullptr, 0);  // now a dead process id
  const fs::path dead = root / fmt::format(".out.tmp-{}-0", child);
  const fs::path dead_file = root / fmt::format(".out.tmp-{}-3", child);
  const fs::path live = root / fmt::format(".out.tmp-{}-0", ::getppid());
  const fs::path other = root / fmt::format(".other.tmp-{}-0", child);
  const fs::path not_staging = root / fmt::format(".out.tmp-{}-x", child);
  fs::create_directories(dead / "depth");
  std::ofstream(dead / "depth" / "a.exr") << "a";
  std::ofstream(dead_file) << "partial";
  for (const fs::path& p : {live, other, not_staging}) fs::create_directories(p);
  {
    StagedDirectory staged(root / "out");
    staged.Commit();
  }
  EXPECT_FALSE(fs::exists(dead));
  EXPECT_FALSE(fs::exists(dead_file));
  for (const fs::path& p : {live, other, not_staging}) EXPECT_TRUE(fs::exists(p)) << p;
}

// Forks a child that runs `body(root, ready_fd, go_fd)`: it stages output
// under `root`, writes a byte to ready_fd when mid-write and, if it ends
// itself, waits for a byte on go_fd first (or its end races the parent's
// look). The parent checks something is staged, then kills the child with
// `sig` or (kill = false) lets it go; the child must end by `sig` and leave
// nothing under `root`.
void ExpectSignalLeavesNothing(int sig, bool kill,
                               const std::function<void(const fs::path&, int, int)>& body) {
  const auto root = test_support::TestOutputDir();
  int ready[2], go[2];
  ASSERT_EQ(::pipe(ready), 0);
  ASSERT_EQ(::pipe(go), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    InstallCleanupSignalHandlers();
    body(root, ready[1], go[0]);
    ::_exit(0);
  }
  char byte = 0;
  ASSERT_EQ(::read(ready[0], &byte, 1), 1);
  EXPECT_GT(Entries(root).size(), 0u);
  if (kill) {
    ::kill(child, sig);
  } else {
    ASSERT_EQ(::write(go[1], "g", 1), 1);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFSIGNALED(status));
  if (WIFSIGNALED(status)) {
    EXPECT_EQ(WTERMSIG(status), sig);
  }
  EXPECT_EQ(Entries(root), std::set<std::string>{}) << "left behind by signal " << sig;
  for (int fd : {ready[0], ready[1], go[0], go[1]}) ::close(fd);
}

// A child stages a folder and a file in it and waits; `sig` must remove the
// staging folder and still end the child by that signal.
void ExpectSignalRemovesStaging(int sig) {
  ExpectSignalLeavesNothing(sig, sig != SIGABRT, [sig](const fs::path& root, int ready, int go) {
    StagedDirectory staged(root / "out");
    fs::create_directories(staged.path() / "color");
    std::ofstream(staged.path() / "color" / "v0.png") << "png";
    AtomicWriteStream(staged.path() / "dataset.json", [&](std::ostream& o) {
      o << "{";
      (void)!::write(ready, "r", 1);
      if (sig == SIGABRT) {
        char go_byte = 0;
        (void)!::read(go, &go_byte, 1);
        std::abort();
      }
      for (;;) ::pause();
    });
  });
}

// A process-directed signal may land on a thread other than the one writing
// (a GL driver's worker): the main thread, still creating files in the
// staging folder, must not leave any behind. The signal is sent to a helper
// thread while the main thread writes as fast as it can.
TEST(StagedDirectory, SignalOnAnotherThreadWhileMainWritesRemovesStaging) {
  ExpectSignalLeavesNothing(SIGTERM, false, [](const fs::path& root, int ready, int go) {
    StagedDirectory staged(root / "out");
    std::thread helper([go] {
      char go_byte = 0;
      (void)!::read(go, &go_byte, 1);
      ::pthread_kill(::pthread_self(), SIGTERM);
      for (;;) ::pause();
    });
    for (long i = 0;; ++i) {
      std::ofstream(staged.path() / fmt::format("f{}", i % 4096)) << i;
      if (i == 64) (void)!::write(ready, "r", 1);
    }
  });
}

TEST(StagedDirectory, SigintRemovesStaging) { ExpectSignalRemovesStaging(SIGINT); }
TEST(StagedDirectory, SigtermRemovesStaging) { ExpectSignalRemovesStaging(SIGTERM); }
TEST(StagedDirectory, SighupRemovesStaging) { ExpectSignalRemovesStaging(SIGHUP); }
TEST(StagedDirectory, AbortRemovesStaging) { ExpectSignalRemovesStaging(SIGABRT); }

}  // namespace
}  // namespace core
