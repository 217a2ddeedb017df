// `ibr export mesh` and `ibr export points` as a user runs them (issue 37):
// the PLY and OBJ files read back by an independent reader (Open3D 0.16,
// Debian's python3-open3d, as MeshLab-compatible tools read them) with the
// counts the command printed, colours and normals present; bad input (no
// depth for a depth object, a missing output folder, an unknown extension)
// is one error line, exit 1 and no file.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>

#include "tests/support/gl_test.h"
#include "tests/support/run_command.h"

namespace {
namespace fs = std::filesystem;
using test_support::CountLines;
using test_support::IbrBinary;
using test_support::Quote;
using test_support::RunCommand;
using test_support::Scratch;

// "V vertices, T triangles" of the command's line (points: "P points").
std::pair<long, long> Counts(const std::string& out) {
  std::smatch m;
  if (std::regex_search(out, m, std::regex("([0-9]+) vertices, ([0-9]+) triangles"))) {
    return {std::stol(m[1]), std::stol(m[2])};
  }
  if (std::regex_search(out, m, std::regex("([0-9]+) points"))) return {std::stol(m[1]), 0};
  return {-1, -1};
}

// Open3D's reading of `file`: "vertices triangles has_colours has_normals".
std::string ReadWithOpen3d(const fs::path& file, bool points) {
  const std::string script =
      points ? "import open3d as o3d,sys\n"
               "p=o3d.io.read_point_cloud(sys.argv[1])\n"
               "print(len(p.points),0,int(p.has_colors()),int(p.has_normals()))\n"
             : "import open3d as o3d,sys\n"
               "m=o3d.io.read_triangle_mesh(sys.argv[1])\n"
               "print(len(m.vertices),len(m.triangles),int(m.has_vertex_colors()),"
               "int(m.has_vertex_normals()))\n";
  const fs::path py = file.parent_path() / "read.py";
  std::ofstream(py) << script;
  const auto r = RunCommand("/usr/bin/python3 " + Quote(py) + " " + Quote(file) + " 2>/dev/null");
  return r.out;
}

class ExportCliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = Scratch("export_cli");
    const auto c = RunCommand(IbrBinary() + " capture --shape sphere --rig cube --size 64 --out " +
                              Quote(dir_ / "sphere"));
    ASSERT_EQ(c.exit_code, 0) << c.out << c.err;
  }
  static fs::path dir_;
};
fs::path ExportCliTest::dir_;

TEST_F(ExportCliTest, PlyAndObjReadBackWithTheirCounts) {
  for (const std::string ext : {"ply", "obj"}) {
    const fs::path out = dir_ / ("sphere." + ext);
    const auto r = RunCommand(IbrBinary() + " export mesh " + Quote(dir_ / "sphere") +
                              " --resolution 64 --out " + Quote(out));
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    const auto [v, t] = Counts(r.out);
    ASSERT_GT(t, 1000) << r.out;
    const std::string read = ReadWithOpen3d(out, false);
    std::printf("%s: ibr %ld vertices %ld triangles; open3d reads: %s", ext.c_str(), v, t,
                read.c_str());
    EXPECT_EQ(read, fmt::format("{} {} 1 1\n", v, t)) << ext;
  }
  EXPECT_TRUE(fs::exists(dir_ / "sphere.mtl"));
}

TEST_F(ExportCliTest, PointsReadBackWithTheirCount) {
  const fs::path out = dir_ / "points.ply";
  const auto r =
      RunCommand(IbrBinary() + " export points " + Quote(dir_ / "sphere") + " --out " + Quote(out));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const auto [n, zero] = Counts(r.out);
  ASSERT_GT(n, 6 * 64 * 64 / 2) << r.out;
  EXPECT_EQ(ReadWithOpen3d(out, true), fmt::format("{} 0 1 1\n", n));
}

TEST_F(ExportCliTest, BadInputIsOneLineAndNoFile) {
  // A dataset whose views have no depth (masks only).
  const fs::path nodepth = dir_ / "nodepth";
  fs::remove_all(nodepth);
  fs::copy(dir_ / "sphere", nodepth, fs::copy_options::recursive);
  nlohmann::json j;
  std::ifstream(nodepth / "dataset.json") >> j;
  for (auto& v : j["views"]) v.erase("depth");
  std::ofstream(nodepth / "dataset.json") << j.dump(1);
  struct Case {
    std::string args, expect;
    fs::path out;
  };
  const std::vector<Case> cases = {
      {"export mesh " + Quote(nodepth), "has no depth map", dir_ / "a.ply"},
      {"export points " + Quote(nodepth), "no view has valid depth", dir_ / "b.ply"},
      {"export mesh " + Quote(dir_ / "sphere"), "does not exist", dir_ / "missing" / "c.ply"},
      {"export mesh " + Quote(dir_ / "sphere"), "unknown mesh format", dir_ / "d.stl"},
      {"export points " + Quote(dir_ / "sphere"), "unknown mesh format", dir_ / "e.obj"},
  };
  for (const Case& c : cases) {
    const auto r = RunCommand(IbrBinary() + " " + c.args + " --out " + Quote(c.out));
    EXPECT_EQ(r.exit_code, 1) << c.args;
    EXPECT_EQ(CountLines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(c.out)) << c.out;
  }
  // The visual hull needs only the masks.
  const auto hull =
      RunCommand(IbrBinary() + " export mesh " + Quote(nodepth) +
                 " --method visual-hull --resolution 48 --out " + Quote(dir_ / "hull.ply"));
  EXPECT_EQ(hull.exit_code, 0) << hull.err;
}

}  // namespace
