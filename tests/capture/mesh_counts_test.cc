// capture/mesh_counts.h: the triangles OBJ, OFF and STL files declare, on
// assimp's real test models (../shared/data/tests-real/meshes) and hand-written files;
// truncations and contradictions refused; mutated bytes only ever read or
// refused (an InputError), never a crash.
#include "capture/mesh_counts.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "tests/support/mutate.h"

namespace capture {
namespace {

const std::filesystem::path kReal = std::filesystem::path(IBR_REAL_DATA_DIR) / "meshes";

std::string Slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

DeclaredFaces Count(const std::string& bytes, const std::string& extension) {
  std::istringstream in(bytes);
  return *CountDeclaredFaces(in, extension, "test" + extension);
}

std::string RefusalOf(const std::string& bytes, const std::string& extension) {
  try {
    Count(bytes, extension);
  } catch (const core::InputError& e) {
    return e.what();
  }
  return "";
}

TEST(MeshCounts, RealFilesDeclareWhatTheyHold) {
  // Cube.off: 6 quads; Spider_binary.stl: its header's count, and the same
  // spider as spider.obj (1368 triangles); sphereWithHole.stl: 285 facets
  // (grep -c endfacet).
  const DeclaredFaces cube = Count(Slurp(kReal / "Cube.off"), ".off");
  EXPECT_EQ(cube.triangles, 12u);
  EXPECT_EQ(cube.corners, 24u);
  const DeclaredFaces spider = Count(Slurp(kReal / "Spider_binary.stl"), ".stl");
  EXPECT_EQ(spider.triangles, 1368u);
  EXPECT_EQ(Count(Slurp(kReal / "spider.obj"), ".obj").triangles, 1368u);
  const DeclaredFaces sphere = Count(Slurp(kReal / "sphereWithHole.stl"), ".stl");
  EXPECT_EQ(sphere.triangles, 285u);
  EXPECT_EQ(sphere.corners, 855u);
  std::istringstream none("ply\n");
  EXPECT_FALSE(CountDeclaredFaces(none, ".ply", "x.ply").has_value());
}

TEST(MeshCounts, HandWrittenFilesAndTheirContradictions) {
  // OFF: counts on the keyword's line, comments, a pentagon (3 triangles),
  // a line face (none).
  EXPECT_EQ(Count("OFF 5 2 0\n# c\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 2 0\n5 0 1 2 3 4\n2 0 1\n", ".off")
                .triangles,
            3u);
  EXPECT_NE(RefusalOf("OFF\n3 1 0\n0 0 0\n1 0 0\n", ".off").find("declares 3 vertices"),
            std::string::npos);
  EXPECT_NE(RefusalOf("OFF\n3 1 0\n0 0 0\n1 0 0\n1 1 0\n3 0 1\n", ".off").find("face 1 of 1"),
            std::string::npos);
  EXPECT_NE(RefusalOf("PLY\n", ".off").find("not OFF"), std::string::npos);
  EXPECT_NE(RefusalOf("OFF\nthree 1 0\n", ".off").find("VERTICES FACES"), std::string::npos);
  // STL: two solids; a facet with 2 vertices; a binary count that lies.
  const std::string facet =
      "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\n"
      "endfacet\n";
  EXPECT_EQ(
      Count("solid a\n" + facet + "endsolid a\nsolid b\n" + facet + facet + "endsolid b\n", ".stl")
          .triangles,
      3u);
  EXPECT_NE(RefusalOf("solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                      "endloop\nendfacet\nendsolid a\n",
                      ".stl")
                .find("facet 1 has 2 vertices, not 3"),
            std::string::npos);
  std::string binary(84 + 50 * 2, '\0');
  const uint32_t three = 3;
  std::memcpy(binary.data() + 80, &three, 4);
  EXPECT_NE(RefusalOf(binary, ".stl").find("declares 3 triangles (234 bytes), the file has 184"),
            std::string::npos);
  binary.resize(84 + 50 * 3);
  EXPECT_EQ(Count(binary, ".stl").triangles, 3u);
  EXPECT_NE(RefusalOf("abc", ".stl").find("shorter than a binary STL header"), std::string::npos);
}

TEST(MeshCounts, MutatedFilesAreReadOrRefusedNeverACrash) {
  const std::vector<std::pair<std::string, std::string>> seeds = {
      {Slurp(kReal / "Cube.off"), ".off"},
      {Slurp(kReal / "sphereWithHole.stl").substr(0, 3000) + "endsolid\n", ".stl"},
      {Slurp(kReal / "Spider_binary.stl").substr(0, 84 + 50 * 20), ".stl"},
      {Slurp(kReal / "spider.obj").substr(0, 3000), ".obj"}};
  std::mt19937 rng(34);
  int ok = 0, refused = 0;
  for (int i = 0; i < 4000; ++i) {
    auto [s, extension] = seeds[i % seeds.size()];
    test_support::MutateBytes(s, rng);
    try {
      Count(s, extension);
      ++ok;
    } catch (const core::InputError&) {
      ++refused;
    }
  }
  EXPECT_GT(refused, 0);
  std::printf("mutated OFF/STL/OBJ files: %d counted, %d refused\n", ok, refused);
}

}  // namespace
}  // namespace capture
