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

// A 64x64 colour texture of four quadrants (red, green, blue, yellow by uv).
core::Image8 QuadrantTexture() {
  core::Image8 t(64, 64, 3);
  const uint8_t colors[4][3] = {{220, 20, 20}, {20, 220, 20}, {20, 20, 220}, {220, 220, 20}};
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      const int q = (x >= 32 ? 1 : 0) + (y >= 32 ? 2 : 0);
      for (int k = 0; k < 3; ++k) t.at(x, y, k) = colors[q][k];
    }
  }
  return t;
}

// The quadrant a lit pixel shows: lighting scales RGB by one factor, so the
// chromaticity decides (nearest of the four); -1 where empty.
int QuadrantOf(const core::Image8& c, int x, int y) {
  if (c.at(x, y, 3) != 255) return -1;
  const float r = c.at(x, y, 0), g = c.at(x, y, 1), b = c.at(x, y, 2);
  const float sum = std::max(1.0f, r + g + b);
  const glm::vec3 chroma(r / sum, g / sum, b / sum);
  const glm::vec3 refs[4] = {{220, 20, 20}, {20, 220, 20}, {20, 20, 220}, {220, 220, 20}};
  int best = 0;
  float best_d = 1e9f;
  for (int q = 0; q < 4; ++q) {
    const glm::vec3 ref = refs[q] / (refs[q].x + refs[q].y + refs[q].z);
    const float d = glm::length(chroma - ref);
    if (d < best_d) best_d = d, best = q;
  }
  return best;
}

// Sign changes of camera z about its mean along the middle row: twice the
// height map's periods across the plane.
int DepthCrossings(const render::Frame& f) {
  const int y = f.depth.height() / 2;
  double sum = 0;
  int n = 0;
  for (int x = 0; x < f.depth.width(); ++x) {
    if (f.Covered(x, y)) sum += f.depth.at(x, y), ++n;
  }
  const double mean = n > 0 ? sum / n : 0;
  int crossings = 0, last = 0;
  for (int x = 0; x < f.depth.width(); ++x) {
    if (!f.Covered(x, y)) continue;
    const double d = f.depth.at(x, y) - mean;
    const int sign = d > 1e-6 ? 1 : d < -1e-6 ? -1 : 0;
    if (sign != 0 && last != 0 && sign != last) ++crossings;
    if (sign != 0) last = sign;
  }
  return crossings;
}

// --tiling repeats the height map, not the colour texture: every method (the
// slicing families, the four ray methods and the tessellated truth) shows
// the same quadrant at the same pixel with tiling 1 and 4 while the depth's
// period shrinks about fourfold; texture_tiling 2 does move the colours.
TEST_F(DisplacedMeshTest, TilingRepeatsHeightsButTheColourTextureKeepsTheMeshUvs) {
  DisplacedMeshData data;
  data.base = DisplacementBaseMesh("plane");
  data.height = DisplacementHeightMap(core::HeightPattern::kBumps, 64, 0.2f);
  data.color = QuadrantTexture();
  const int size = 96;
  OrbitCamera top;
  top.elevation_deg = 90;
  const float md = 0.1f;
  const render::ViewSetup view = DisplacementOrbitView(data.base, md, top, size);
  for (const std::string& name : DisplacementMethodNames()) {
    DisplacedMeshOptions o;
    o.method = DisplacementMethodFromName(name);
    o.max_displacement = md;
    o.slices = 32;
    auto render = [&](float tiling, float texture_tiling) {
      o.tiling = tiling;
      o.texture_tiling = texture_tiling;
      DisplacedMeshRenderer r(programs(), data, o);
      r.Draw(view, size, size);
      return r.Read();
    };
    const render::Frame t1 = render(1, 1), t4 = render(4, 1), moved = render(1, 2);
    int samples = 0, same = 0, same_moved = 0;
    int counts[4] = {0, 0, 0, 0};
    double brightness_change = 0;  // mean |R+G+B difference| where the quadrant is the same
    for (int y = 4; y < size; y += 4) {
      for (int x = 4; x < size; x += 4) {
        const int a = QuadrantOf(t1.color, x, y), b = QuadrantOf(t4.color, x, y);
        if (a < 0 || b < 0) continue;
        ++samples;
        ++counts[a];
        same += a == b;
        same_moved += a == QuadrantOf(moved.color, x, y);
        if (a == b) {
          int d = 0;
          for (int k = 0; k < 3; ++k) d += t1.color.at(x, y, k) - t4.color.at(x, y, k);
          brightness_change += std::abs(d);
        }
      }
    }
    brightness_change /= std::max(1, same);
    ASSERT_GT(samples, 150) << name;
    // Parallax shifts a pixel's uv by less than the bumps' height: only pixels
    // near the quadrant borders may change.
    EXPECT_GT(same, 0.9 * samples) << name;
    EXPECT_LT(same_moved, 0.6 * samples) << name;  // the texture itself tiles when asked
    for (int q = 0; q < 4; ++q) EXPECT_GT(counts[q], samples / 8) << name << " quadrant " << q;
    const int c1 = DepthCrossings(t1), c4 = DepthCrossings(t4);
    EXPECT_GE(c1, 2) << name;
    EXPECT_GE(2 * c4, 5 * c1) << name << ": " << c1 << " vs " << c4;  // about 4x, >= 2.5x
    if (same <= 0.9 * samples || 2 * c4 < 5 * c1) {
      test_support::WriteDebugImage(name + "_t1.png", t1.color);
      test_support::WriteDebugImage(name + "_t4.png", t4.color);
    }
    // The colour is lit with the displaced normal: other bumps, other shading
    // inside the surface, not only at its outline.
    EXPECT_GT(brightness_change, 20.0) << name;
    fmt::print(
        "{}: {} of {} samples keep their quadrant, depth crossings {} -> {}, mean brightness "
        "change {:.1f} / 765\n",
        name, same, samples, c1, c4, brightness_change);
  }
  EXPECT_NO_GL_ERROR();
}

// The orbit's --up: the same mesh turned so that y is up, seen with up y,
// gives the image of the original seen with up z.
TEST_F(DisplacedMeshTest, UpAxisTurnsTheOrbit) {
  DisplacedMeshData z_up;
  z_up.base = DisplacementBaseMesh("torus");
  z_up.height = DisplacementHeightMap(core::HeightPattern::kBumps, 32, 0.1f);
  DisplacedMeshData y_up = z_up;
  // (x, y, z) -> (y, z, x): z's role goes to y, x's to z, y's to x, so the
  // orbit frame (h1, h2, up) = (x, y, z) maps to (z, x, y), the frame for up y.
  for (glm::vec3& p : y_up.base.positions) p = glm::vec3(p.y, p.z, p.x);
  for (glm::vec3& n : y_up.base.normals) n = glm::vec3(n.y, n.z, n.x);
  OrbitCamera orbit;
  const render::ViewSetup vz = DisplacementOrbitView(z_up.base, 0.1f, orbit, 96);
  orbit.up = UpAxisFromName("y", "test");
  const render::ViewSetup vy = DisplacementOrbitView(y_up.base, 0.1f, orbit, 96);
  DisplacedMeshOptions o;
  o.method = DisplacementMethod::kTessellated;
  o.max_displacement = 0.1f;
  DisplacedMeshRenderer a(programs(), z_up, o), b(programs(), y_up, o);
  a.Draw(vz, 96, 96);
  b.Draw(vy, 96, 96);
  const render::Frame fa = a.Read(), fb = b.Read();
  const core::ViewMetrics d = core::CompareFrames(fb.color, fb.depth, fa.color, fa.depth);
  EXPECT_GT(d.truth_pixels, 1000);
  EXPECT_GT(d.iou, 0.999);
  EXPECT_LT(d.depth.p95, 1e-4);
  EXPECT_THROW(UpAxisFromName("w", "test"), core::InputError);
  EXPECT_THROW(UpAxisFromName("--y", "test"), core::InputError);
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace ibr
