// PLY and OBJ writing (core/mesh_write.h): a binary PLY read back by our PLY
// reader gives the same positions, normals and triangles bit for bit; the
// header declares colours only when given and no face element for points;
// the OBJ names its material file and writes 1-based faces with normals;
// bad output paths are refused before anything is written. Signed volumes
// and Chamfer distances of known shapes (core/mesh_compare.h).
#include "core/mesh_write.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <numbers>
#include <sstream>

#include "core/error.h"
#include "core/mesh_compare.h"
#include "core/ply_io.h"

namespace core {
namespace {

TEST(MeshWrite, PlyRoundTripsThroughOurReader) {
  TriangleMesh box = MakeBox({1.0f, 0.5f, 0.25f});
  std::vector<glm::u8vec3> colours(box.positions.size());
  for (size_t i = 0; i < colours.size(); ++i) colours[i] = glm::u8vec3(i, 2 * i, 255 - i);
  std::stringstream s;
  WritePlyMesh(s, box, colours);
  const std::string text = s.str();
  EXPECT_NE(text.find("format binary_little_endian 1.0"), std::string::npos);
  EXPECT_NE(text.find("property uchar red"), std::string::npos);
  const PlyMesh back = ReadPly(s, "round trip");
  ASSERT_EQ(back.mesh.positions.size(), box.positions.size());
  ASSERT_EQ(back.mesh.indices, box.indices);
  for (size_t i = 0; i < box.positions.size(); ++i) {
    EXPECT_EQ(back.mesh.positions[i], box.positions[i]);
    EXPECT_EQ(back.mesh.normals[i], box.normals[i]);
  }
  // Points: no face element at all, no colours when none are given.
  TriangleMesh points;
  points.positions = {{0, 0, 0}, {1, 2, 3}};
  std::stringstream p;
  WritePlyMesh(p, points, {});
  EXPECT_EQ(p.str().find("element face"), std::string::npos);
  EXPECT_EQ(p.str().find("red"), std::string::npos);
  EXPECT_EQ(p.str().size(), p.str().find("end_header\n") + 11 + 2 * 12);
}

TEST(MeshWrite, ObjNamesItsMaterialAndWritesOneBasedFaces) {
  TriangleMesh tri;
  tri.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  tri.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  tri.indices = {0, 1, 2};
  std::stringstream s;
  WriteObjMesh(s, tri, {glm::u8vec3(255, 0, 0), glm::u8vec3(0, 255, 0), glm::u8vec3(0, 0, 255)},
               "x.mtl");
  const std::string t = s.str();
  EXPECT_NE(t.find("mtllib x.mtl\n"), std::string::npos);
  EXPECT_NE(t.find("v 1 0 0 0 1 0\n"), std::string::npos) << t;
  EXPECT_NE(t.find("usemtl ibr_object\nf 1//1 2//2 3//3\n"), std::string::npos) << t;
}

TEST(MeshWrite, BadPathsAreRefusedWithoutAFile) {
  const auto dir = std::filesystem::temp_directory_path() / "ibr_mesh_write_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const TriangleMesh box = MakeBox({1, 1, 1});
  EXPECT_THROW(WriteMeshFile(dir / "missing" / "a.ply", box, {}), InputError);
  EXPECT_THROW(WriteMeshFile(dir / "a.stl", box, {}), InputError);
  EXPECT_THROW(CheckMeshFilePath("points", dir / "a.obj", /*allow_obj=*/false), InputError);
  EXPECT_TRUE(std::filesystem::is_empty(dir));
  WriteMeshFile(dir / "a.obj", box, {});
  EXPECT_TRUE(std::filesystem::exists(dir / "a.mtl"));
  std::filesystem::remove_all(dir);
}

TEST(MeshCompare, VolumesAndDistancesOfKnownShapes) {
  const TriangleMesh box = MakeBox({1.0f, 0.5f, 0.25f});
  EXPECT_NEAR(SignedVolume(box), 2.0 * 1.0 * 0.5, 1e-6);
  TriangleMesh inverted = box;
  for (size_t t = 0; t < inverted.indices.size(); t += 3) {
    std::swap(inverted.indices[t + 1], inverted.indices[t + 2]);
  }
  EXPECT_NEAR(SignedVolume(inverted), -1.0, 1e-6);
  // A box against itself moved by 0.01 along x: every distance <= 0.01.
  TriangleMesh moved = box;
  for (glm::vec3& p : moved.positions) p.x += 0.01f;
  const MeshComparison c = CompareMeshes(moved, box, 20000, 1.0);
  EXPECT_LE(c.a_to_b_max, 0.01 + 1e-6);
  EXPECT_GT(c.a_to_b_p95, 0.009);  // the moved +x face lies 0.01 away
  // Alike, except samples of the moved side faces past the box's +x face,
  // whose closest point lies on an edge (either face's normal): 1 % of them.
  EXPECT_GT(c.normal_agreement, 0.98);
  EXPECT_NEAR(CompareMeshes(inverted, box, 1000, 1.0).normal_agreement, -1.0, 1e-6);
  EXPECT_NEAR(BoundsDiagonal(box), std::sqrt(4.0 + 1.0 + 0.25), 1e-6);
}

}  // namespace
}  // namespace core
