// A user's own file at every output path of every command: the command
// refuses in one line naming the file, exits non-zero, and the file is
// byte-identical afterwards, with no staging file left beside it. An earlier
// ibr output at the same path is replaced with one line saying so, and
// --overwrite is the one way past the rule (core/atomic_file.h;
// docs/guide/limits.md).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/run_command.h"

namespace {
namespace fs = std::filesystem;
using test_support::CountLines;
using test_support::IbrBinary;
using test_support::Quote;
using test_support::RunCommand;
using test_support::Scratch;
using test_support::Slurp;
using test_support::Spit;

fs::path SharedData() {
  const char* shared = std::getenv("IBR_SHARED_DATA");
  return shared ? fs::path(shared) : fs::path("../shared/data");
}

fs::path Capture(const std::string& rig) {
  const fs::path d = Scratch("user_files_fixture_" + rig.substr(0, rig.find(':')));
  const auto r = RunCommand(IbrBinary() + " --log-level error capture --shape sphere --rig " + rig +
                            " --size 32 --out " + Quote(d / "data"));
  if (r.exit_code != 0) ADD_FAILURE() << "fixture capture failed: " << r.err;
  return d / "data";
}

// A 6-view cube capture of the sphere, 32 px, made once; and a ring of 4
// perspective views (what COLMAP takes).
const fs::path& Dataset() {
  static const fs::path dataset = Capture("cube");
  return dataset;
}
const fs::path& Ring() {
  static const fs::path dataset = Capture("ring:4");
  return dataset;
}

// Names of everything in `dir` but the user's file: nothing may be added.
std::vector<std::string> Others(const fs::path& dir, const fs::path& mine) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().filename() != mine.filename()) names.push_back(e.path().filename().string());
  }
  return names;
}

struct OutputCase {
  std::string name;
  std::string args;  // after `ibr`; MINE is the user's file
  std::string mine;  // its file name
  std::string expect = "ibr did not write it";
};

std::vector<OutputCase> Cases() {
  const std::string cube = Quote(Dataset());
  const std::string mesh = Quote(SharedData() / "meshes" / "spot.obj");
  const std::string volume = Quote(SharedData() / "volumes" / "Bucky_32x32x32_uint8.dat");
  return {
      {"volume_png", "volume " + volume + " --size 32 --out MINE", "mine.png"},
      {"displace_png", "displace --size 32 --frames 0 --out MINE", "mine_d.png"},
      // The depth image beside the PNG is refused before the PNG is written.
      {"displace_depth_exr", "displace --size 32 --frames 0 --out DIR/mine_d.png",
       "mine_d.depth.exr"},
      {"deform_png", "deform " + mesh + " --resolution 16 --size 32 --out MINE", "mine.png"},
      {"export_mesh_ply", "export mesh " + cube + " --resolution 16 --out MINE", "mine.ply"},
      {"export_mesh_obj", "export mesh " + cube + " --resolution 16 --out MINE", "mine.obj"},
      {"export_mesh_mtl", "export mesh " + cube + " --resolution 16 --out DIR/mine.obj", "mine.mtl",
       "was not written by ibr"},
      {"export_points_ply", "export points " + cube + " --out MINE", "mine.ply"},
      {"view_screenshot", "view " + cube + " --screenshot MINE", "mine.png"},
      {"view_frame_out", "view " + cube + " --screenshot DIR/s.png --frame-out MINE", "mine.png"},
      {"view_camera_out", "view " + cube + " --screenshot DIR/s.png --camera-out MINE",
       "mine.json"},
      {"view_save_scene", "view " + cube + " --screenshot DIR/s.png --save-scene MINE",
       "mine.json"},
      {"bench_csv", "bench viewer --quick --csv MINE", "mine.csv"},
      {"bench_depth_object_csv", "bench depth-object --quick --csv MINE", "mine.csv"},
      // Folder outputs: a file of the user's where the folder would go.
      {"capture_folder", "capture --shape sphere --rig cube --size 16 --out MINE", "mine",
       "not a folder"},
      {"render_folder", "render " + cube + " --orbit 1 --size 16 --out MINE", "mine",
       "not a folder"},
      {"verify_folder", "verify --cases 1 --out MINE", "mine", "not a folder"},
      {"export_colmap_folder", "export colmap " + Quote(Ring()) + " --out MINE", "mine",
       "not a folder"},
      {"demo_folder", "demo --out MINE", "mine", "not a folder"},
  };
}

TEST(UserFiles, EveryOutputPathKeepsTheUsersFile) {
  for (const OutputCase& c : Cases()) {
    SCOPED_TRACE(c.name);
    const fs::path dir = Scratch("user_files_" + c.name);
    const fs::path mine = dir / c.mine;
    const std::string precious = "precious: " + c.name + "\n";
    Spit(mine, precious);
    std::string args = c.args;
    for (const auto& [token, value] :
         {std::pair<std::string, std::string>{"MINE", Quote(mine)}, {"DIR", dir.string()}}) {
      for (size_t at; (at = args.find(token)) != std::string::npos;)
        args.replace(at, token.size(), value);
    }
    const auto r = RunCommand(IbrBinary() + " --log-level error " + args);
    EXPECT_NE(r.exit_code, 0) << r.err;
    EXPECT_EQ(CountLines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("ibr: error: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(c.mine), std::string::npos) << "names the file: " << r.err;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << r.err;
    EXPECT_EQ(Slurp(mine), precious);
    EXPECT_TRUE(Others(dir, mine).empty()) << "left beside it: " << Others(dir, mine).front();
  }
}

// An earlier output of ibr's at the same path is replaced, with one line
// saying so; a user's file only with --overwrite.
TEST(UserFiles, EarlierOutputsAreReplacedAndSaySo) {
  const fs::path dir = Scratch("user_files_replace");
  for (const char* name : {"m.ply", "m.obj"}) {
    SCOPED_TRACE(name);
    const std::string cmd = IbrBinary() + " export mesh " + Quote(Dataset()) +
                            " --resolution 16 --out " + Quote(dir / name);
    const auto first = RunCommand(cmd);
    ASSERT_EQ(first.exit_code, 0) << first.err;
    EXPECT_EQ(first.err.find("replacing"), std::string::npos) << first.err;
    const auto second = RunCommand(cmd);
    ASSERT_EQ(second.exit_code, 0) << second.err;
    EXPECT_NE(second.err.find("replacing '" + (dir / name).string() + "', an earlier ibr output"),
              std::string::npos)
        << second.err;
  }
  // PNG (a text chunk) and its EXR (a header attribute) carry the mark too.
  const std::string displace =
      IbrBinary() + " displace --size 32 --frames 0 --out " + Quote(dir / "d.png");
  ASSERT_EQ(RunCommand(displace).exit_code, 0);
  const auto again = RunCommand(displace);
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_NE(again.err.find("d.png', an earlier ibr output"), std::string::npos) << again.err;
  EXPECT_NE(again.err.find("d.depth.exr', an earlier ibr output"), std::string::npos) << again.err;

  // A folder output: an earlier capture of another shape is replaced, and the
  // line names the command that wrote it.
  for (const char* shape : {"sphere", "torus"}) {
    const auto r = RunCommand(IbrBinary() + " capture --shape " + shape +
                              " --rig cube --size 16 --out " + Quote(dir / "capture"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const bool said =
        r.err.find("replacing '" + (dir / "capture").string() +
                   "', an earlier ibr output (ibr capture --shape sphere") != std::string::npos;
    EXPECT_EQ(said, std::string(shape) == "torus") << r.err;
  }

  Spit(dir / "yours.ply", "mine\n");
  const auto refused = RunCommand(IbrBinary() + " export points " + Quote(Dataset()) + " --out " +
                                  Quote(dir / "yours.ply"));
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_EQ(Slurp(dir / "yours.ply"), "mine\n");
  const auto forced = RunCommand(IbrBinary() + " export points " + Quote(Dataset()) + " --out " +
                                 Quote(dir / "yours.ply") + " --overwrite");
  ASSERT_EQ(forced.exit_code, 0) << forced.err;
  EXPECT_NE(forced.err.find("(--overwrite)"), std::string::npos) << forced.err;
  EXPECT_NE(Slurp(dir / "yours.ply"), "mine\n");
}

}  // namespace
