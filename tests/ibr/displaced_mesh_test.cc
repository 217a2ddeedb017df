// ibr/displaced_mesh.h: the method table, the user's own height maps (8-bit,
// 16-bit PNG, EXR) and meshes (OBJ with uvs), rendered like the built-ins.
#include "ibr/displaced_mesh.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "core/error.h"
#include "core/image_io.h"
#include "core/metrics.h"
#include "core/projection.h"
#include "tests/support/gl_test.h"

namespace ibr {
namespace {
namespace fs = std::filesystem;

TEST(DisplacementMethods, NamesRoundTripAndUnknownIsAnError) {
  const std::vector<std::string> names = DisplacementMethodNames();
  EXPECT_EQ(names.size(), 8u);
  for (const std::string& n : names)
    EXPECT_EQ(DisplacementMethodName(DisplacementMethodFromName(n)), n);
  EXPECT_THROW(DisplacementMethodFromName("slices"), core::InputError);
}

TEST(ReadHeightMap, EightAndSixteenBitPngAndExrGiveTheSameHeights) {
  const fs::path dir = test_support::TestOutputDir();
  core::Image8 h8(4, 2, 1);
  core::Image<uint16_t> h16(4, 2, 1);
  core::ImageF hf(4, 2, 1);
  for (int i = 0; i < 8; ++i) {
    h8.data()[i] = static_cast<uint8_t>(i * 255 / 7);
    h16.data()[i] = static_cast<uint16_t>(i * 65535 / 7);
    hf.data()[i] = static_cast<float>(i) / 7.0f;
  }
  core::WriteImage(dir / "h8.png", h8);
  core::WriteImage(dir / "h16.png", h16);
  core::WriteImage(dir / "hf.exr", hf);
  const core::ImageF a = ReadHeightMap(dir / "h8.png"), b = ReadHeightMap(dir / "h16.png"),
                     c = ReadHeightMap(dir / "hf.exr");
  for (int i = 0; i < 8; ++i) {
    // The stored integers scaled to [0, 1] (float rounding only).
    EXPECT_NEAR(a.data()[i], h8.data()[i] / 255.0, 1e-6) << i;
    EXPECT_NEAR(b.data()[i], h16.data()[i] / 65535.0, 1e-6) << i;
    EXPECT_EQ(c.data()[i], hf.data()[i]);  // float EXR round-trips exactly
  }
  hf.at(1, 1) = 1.5f;
  core::WriteImage(dir / "bad.exr", hf);
  EXPECT_THROW(ReadHeightMap(dir / "bad.exr"), core::InputError);
  EXPECT_THROW(ReadHeightMap(dir / "absent.png"), core::InputError);
}

// The built-in torus written as OBJ (v flipped: LoadSceneMesh flips it back).
void WriteObj(const core::TriangleMesh& m, const fs::path& path, bool with_uvs) {
  std::ofstream out(path);
  for (const glm::vec3& p : m.positions) out << fmt::format("v {} {} {}\n", p.x, p.y, p.z);
  for (const glm::vec3& n : m.normals) out << fmt::format("vn {} {} {}\n", n.x, n.y, n.z);
  if (with_uvs) {
    for (const glm::vec2& t : m.uvs) out << fmt::format("vt {} {}\n", t.x, 1.0f - t.y);
  }
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    out << "f";
    for (int k = 0; k < 3; ++k) {
      const uint32_t i = m.indices[3 * t + k] + 1;
      out << (with_uvs ? fmt::format(" {}/{}/{}", i, i, i) : fmt::format(" {}//{}", i, i));
    }
    out << "\n";
  }
}

class DisplacedMeshTest : public test_support::GlTest {};

// The user's path (OBJ + 16-bit PNG height map) renders the same surface as
// the built-in torus with the same heights.
TEST_F(DisplacedMeshTest, UsersMeshAndHeightMapMatchTheBuiltIn) {
  const fs::path dir = test_support::TestOutputDir();
  DisplacedMeshData builtin;
  builtin.base = DisplacementBaseMesh("torus");
  builtin.height = DisplacementHeightMap(core::HeightPattern::kBumps, 64, 0.1f);
  core::Image<uint16_t> h16(64, 64, 1);
  for (size_t p = 0; p < h16.pixel_count(); ++p) {
    h16.data()[p] = static_cast<uint16_t>(std::lround(builtin.height.data()[p] * 65535.0f));
  }
  core::WriteImage(dir / "height.png", h16);
  WriteObj(builtin.base, dir / "torus.obj", true);
  DisplacedMeshData user;
  user.base = ReadDisplacementBase(dir / "torus.obj");
  user.height = ReadHeightMap(dir / "height.png");

  DisplacedMeshOptions o;
  o.slices = 24;
  o.tiling = 2;
  const int size = 128;
  const render::ViewSetup view = [&] {
    render::ViewSetup v;
    v.cam_from_world = glm::mat4(1.0f);
    v.cam_from_world[3] = glm::vec4(0, 0, 5, 1);  // torus around z, seen along +z
    v.clip_from_cam = core::ClipFromCamPerspective(150, 150, 64, 64, size, size, 2.0, 8.0);
    return v;
  }();
  for (DisplacementMethod m : {DisplacementMethod::kSlicesOrthogonal, DisplacementMethod::kNcs}) {
    o.method = m;
    DisplacedMeshRenderer a(programs(), builtin, o), b(programs(), user, o);
    a.Draw(view, size, size);
    const render::Frame fa = a.Read();
    b.Draw(view, size, size);
    const render::Frame fb = b.Read();
    const core::ViewMetrics d = core::CompareFrames(fb.color, fb.depth, fa.color, fa.depth);
    EXPECT_GT(d.truth_pixels, 2000) << DisplacementMethodName(m);
    // OBJ text rounds positions to 6 digits and heights to 16 bits: a handful
    // of silhouette pixels may flip.
    EXPECT_GT(d.iou, 0.995) << DisplacementMethodName(m);
    EXPECT_LT(d.depth.p95, 1e-3) << DisplacementMethodName(m);
  }
  WriteObj(builtin.base, dir / "no_uvs.obj", false);
  EXPECT_THROW(ReadDisplacementBase(dir / "no_uvs.obj"), core::InputError);
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace ibr
