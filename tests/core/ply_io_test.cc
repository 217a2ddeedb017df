// core/ply_io: triangle strips decoded with the restart and winding rules,
// real third-party PLY files (MeshLab's tristrip brain, a Cyberware scanner
// export in big-endian binary, a per-corner texcoord knot) read to the counts
// computed independently from their bytes, and every lying or broken file
// refused in one line (never a partial mesh).
#include "core/ply_io.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>

#include "core/memory_budget.h"
#include "tests/support/input_error.h"
#include "tests/support/mutate.h"

namespace core {
namespace {

namespace fs = std::filesystem;
using test_support::InputErrorOf;

const fs::path kReal = fs::path(IBR_REAL_DATA_DIR) / "meshes";

PlyMesh ReadText(const std::string& text) {
  std::istringstream in(text);
  return ReadPly(in, "test.ply");
}

std::string Slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Directed edges used by more than one triangle: 0 on a consistently wound
// manifold surface. A strip decoded with the wrong parity flips every other
// triangle, which repeats directed edges along the strip.
int64_t RepeatedDirectedEdges(const TriangleMesh& m) {
  std::map<std::pair<uint32_t, uint32_t>, int> count;
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    for (int k = 0; k < 3; ++k) {
      ++count[{m.indices[3 * t + k], m.indices[3 * t + (k + 1) % 3]}];
    }
  }
  int64_t repeated = 0;
  for (const auto& [edge, n] : count) repeated += n > 1;
  return repeated;
}

const char* kSquareHeader =
    "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
    "property float z\n";
const char* kSquareVertices = "0 0 0\n1 0 0\n0 1 0\n1 1 0\n2 0 0\n";

TEST(Ply, TriangleStripRestartAndAlternatingWindingByHand) {
  // Strip 0 1 2 3 | 2 4 0: (0,1,2), (2,1,3) (the odd one swaps its first two),
  // then after -1 (2,4,0). All three counter-clockwise seen from +z except the
  // last run's own order, which the file gives.
  const PlyMesh m = ReadText(std::string(kSquareHeader) +
                             "element tristrips 1\nproperty list int int vertex_indices\n"
                             "end_header\n" +
                             kSquareVertices + "8 0 1 2 3 -1 2 4 0\n");
  EXPECT_EQ(m.mesh.indices, (std::vector<uint32_t>{0, 1, 2, 2, 1, 3, 2, 4, 0}));
  EXPECT_EQ(m.strips, 2u);
  EXPECT_EQ(m.strip_triangles, 3u);
  // The first two share the edge 1-2 in opposite directions: one winding.
  EXPECT_EQ(RepeatedDirectedEdges(m.mesh), 0);
  // Zero-area joins (a repeated index) are dropped, the parity kept.
  const PlyMesh j = ReadText(std::string(kSquareHeader) +
                             "element tristrips 1\nproperty list int int vertex_indices\n"
                             "end_header\n" +
                             kSquareVertices + "6 0 1 2 2 3 4\n");
  // 0 1 2 | (2 1 2) | (2 2 3) | (3 2 4): k = 3 is odd, so s[4] s[3] s[5].
  EXPECT_EQ(j.mesh.indices, (std::vector<uint32_t>{0, 1, 2, 3, 2, 4}));
  EXPECT_EQ(j.dropped_degenerate, 2u);
}

TEST(Ply, PolygonsAreFannedAndCountsMustMatchTheBody) {
  auto with_faces = [&](int declared, const std::string& faces) {
    return std::string(kSquareHeader) + "element face " + std::to_string(declared) +
           "\nproperty list uchar int vertex_indices\nend_header\n" + kSquareVertices + faces;
  };
  const PlyMesh quad = ReadText(with_faces(1, "4 0 1 3 2\n"));
  EXPECT_EQ(quad.mesh.indices, (std::vector<uint32_t>{0, 1, 3, 0, 3, 2}));
  EXPECT_EQ(quad.faces, 1u);
  // A header that says fewer faces than the body holds, or more.
  EXPECT_EQ(InputErrorOf([&] { ReadText(with_faces(1, "3 0 1 2\n3 1 4 3\n")); }),
            "test.ply: 8 bytes of data follow the last element the header declares: an element "
            "count is wrong (the file holds more than its header says)");
  EXPECT_EQ(InputErrorOf([&] { ReadText(with_faces(3, "3 0 1 2\n3 1 4 3\n")); }),
            "test.ply: face 2: the file ends here");
  EXPECT_EQ(InputErrorOf([&] { ReadText(with_faces(1, "3 0 1 5\n")); }),
            "test.ply: face 0: vertex index 5 is out of range (5 vertices)");
  EXPECT_EQ(InputErrorOf([&] { ReadText(with_faces(1, "2 0 1\n")); }),
            "test.ply: face 0 has 2 vertex indices (a face needs at least 3)");
}

TEST(Ply, FacesThatCannotBeDecodedAreRefusedNotDropped) {
  // A scanner's range grid carries the surface in a list this reader does not
  // triangulate: refused, not loaded as a point set.
  EXPECT_EQ(InputErrorOf([&] {
              ReadText(std::string(kSquareHeader) +
                       "element range_grid 4\nproperty list uchar int vertex_indices\n"
                       "element face 0\nproperty list uchar int vertex_indices\nend_header\n" +
                       kSquareVertices + "1 0\n1 1\n1 2\n0\n");
            }),
            "test.ply: element 'range_grid' (4 rows) holds vertex indices this reader does not "
            "decode (only 'face' and 'tristrips'); its surface would be lost: convert the file "
            "to faces first (e.g. MeshLab)");
  EXPECT_EQ(InputErrorOf(
                [&] { ReadText(std::string(kSquareHeader) + "end_header\n" + kSquareVertices); }),
            "test.ply: no 'face' or 'tristrips' element: a point cloud (5 vertices), not a mesh");
}

TEST(Ply, RealTristripBrainHasTheTrianglesItsStripsHold) {
  // MeshLab's sample/brain.ply: one `tristrips` row of 54404 indices. The
  // counts below were computed from the file's bytes by count_strips.py
  // (beside the file), which reads the strips independently of this reader.
  const PlyMesh m = ReadPly(kReal / "brain.ply");
  EXPECT_EQ(m.mesh.positions.size(), 18844u);
  EXPECT_EQ(m.strips, 5884u);
  EXPECT_EQ(m.strip_triangles, 36752u);
  EXPECT_EQ(m.mesh.triangle_count(), 36752u);
  EXPECT_EQ(m.dropped_degenerate, 0u);
  // The alternating winding makes the surface consistently oriented.
  EXPECT_EQ(RepeatedDirectedEdges(m.mesh), 0);
  std::printf("brain.ply: %zu vertices, %zu triangles from %llu strips\n", m.mesh.positions.size(),
              m.mesh.triangle_count(), static_cast<unsigned long long>(m.strips));
}

TEST(Ply, RealBigEndianScannerExport) {
  // MeshLab's sample/screwdriver.ply (Cyberware, decimated): binary big
  // endian, a per-vertex confidence, 6789 vertices and 13574 triangles as
  // its header says.
  const PlyMesh m = ReadPly(kReal / "screwdriver.ply");
  EXPECT_EQ(m.mesh.positions.size(), 6789u);
  EXPECT_EQ(m.faces, 13574u);
  EXPECT_EQ(m.mesh.triangle_count(), 13574u);
  EXPECT_EQ(RepeatedDirectedEdges(m.mesh), 0);
  glm::vec3 lo, hi;
  m.mesh.Bounds(lo, hi);
  // Read in the wrong byte order the coordinates would be garbage (or not finite).
  EXPECT_LT(glm::length(hi - lo), 1e3f);
  EXPECT_GT(glm::length(hi - lo), 1e-3f);
}

TEST(Ply, RealPerCornerTexcoordsAndTextureComment) {
  const PlyMesh m = ReadPly(kReal / "texturedknot.ply");
  EXPECT_EQ(m.faces, 2880u);
  EXPECT_EQ(m.mesh.triangle_count(), 2880u);
  EXPECT_EQ(m.mesh.uvs.size(), m.mesh.positions.size());
  EXPECT_EQ(m.texture_file, "TextureDouble_A.png");
}

TEST(Ply, LyingCountsInARealBinaryFileAreRefused) {
  const std::string bytes = Slurp(kReal / "screwdriver.ply");
  const std::string declared = "element face      13574";
  ASSERT_NE(bytes.find(declared), std::string::npos);
  auto with_count = [&](const std::string& count) {
    std::string b = bytes;
    std::string line = "element face " + count;
    line.resize(declared.size(), ' ');  // same header length, same body offset
    b.replace(b.find(declared), declared.size(), line);
    std::istringstream in(b);
    return InputErrorOf([&] { ReadPly(in, "screwdriver.ply"); });
  };
  // Fewer declared than held: the rest of the body is left over.
  EXPECT_EQ(with_count("13000"),
            "screwdriver.ply: 7462 bytes of data follow the last element the header declares: "
            "an element count is wrong (the file holds more than its header says)");
  // More declared than held: the body ends inside the first face it lacks.
  EXPECT_EQ(with_count("14000"), "screwdriver.ply: face 13574: the file ends here");
  // Far more: refused from the header's counts before any face is read.
  EXPECT_EQ(with_count("999999"),
            "screwdriver.ply: the header's element counts need at least 1108623 bytes of data, "
            "the file holds 285086: it is truncated or a count is wrong");
}

TEST(Ply, MemoryBudgetIsCheckedBeforeTheBodyIsRead) {
  SetMemoryBudget(100000);  // 100 kB: brain.ply's mesh needs ~600 kB
  const std::string error = InputErrorOf([&] { ReadPly(kReal / "brain.ply"); });
  SetMemoryBudget(std::nullopt);
  EXPECT_NE(error.find("over the memory budget"), std::string::npos) << error;
}

TEST(Ply, ArbitraryBytesGiveInputErrorsOnly) {
  // Deterministic mutations of valid files (ascii and binary): each read
  // either succeeds or throws InputError; nothing else escapes.
  const std::vector<std::string> seeds = {
      std::string(kSquareHeader) +
          "element tristrips 1\nproperty list int int vertex_indices\nend_header\n" +
          kSquareVertices + "8 0 1 2 3 -1 2 4 0\n",
      Slurp(kReal / "screwdriver.ply").substr(0, 4000)};
  std::mt19937 rng(34);
  int ok = 0, refused = 0;
  for (int i = 0; i < 4000; ++i) {
    std::string s = seeds[i % seeds.size()];
    test_support::MutateBytes(s, rng);
    std::istringstream in(s);
    try {
      ReadPly(in, "fuzz.ply");
      ++ok;
    } catch (const InputError&) {
      ++refused;
    }
  }
  EXPECT_GT(refused, 0);
  std::printf("mutated PLY files: %d read, %d refused\n", ok, refused);
}

}  // namespace
}  // namespace core
