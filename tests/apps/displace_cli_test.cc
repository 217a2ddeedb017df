// `ibr displace` on a real third-party mesh (../shared/data/tests-real/displace: Keenan
// Crane's Spot control mesh, 180 quads with uvs, and its colour texture):
// the tessellated truth under an 8 GB address-space limit renders or is
// refused in one line, never a signal; the colour texture stays at the
// mesh's uvs under --tiling for every method; an opaque background.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/image_io.h"
#include "core/mesh.h"
#include "tests/support/gl_test.h"
#include "tests/support/run_command.h"

namespace {
namespace fs = std::filesystem;
using test_support::CountLines;
using test_support::IbrBinary;
using test_support::RunCommand;

const fs::path kReal = fs::path(IBR_REAL_DATA_DIR) / "displace";

std::string Quote(const fs::path& p) { return fmt::format("'{}'", p.string()); }

// Spot stands on y = min (--up y).
std::string Spot(const std::string& up = "y") {
  return " --mesh " + Quote(kReal / "spot_control_mesh.obj") + " --texture " +
         Quote(kReal / "spot_texture.png") + " --up " + up + " --max-displacement 0.03";
}

// Exit 0 with a decodable image, or exit 1 with one `ibr: error:` line about
// the memory budget; anything else (a signal: 128 + n from sh, or -1) fails.
void ExpectRendersOrIsRefused(const test_support::CommandResult& r, const fs::path& out) {
  ASSERT_TRUE(r.exit_code == 0 || r.exit_code == 1) << "exit " << r.exit_code << "\n"
                                                    << r.out << r.err;
  if (r.exit_code == 0) {
    EXPECT_NE(r.out.find("tessellated truth:"), std::string::npos) << r.out;
    const core::Image8 color = core::ReadImage<uint8_t>(out);
    int covered = 0;
    for (size_t p = 0; p < color.pixel_count(); ++p) covered += color.data()[4 * p + 3] == 255;
    EXPECT_GT(covered, 100);
  } else {
    EXPECT_EQ(CountLines(r.err), 1) << r.err;
    EXPECT_EQ(r.err.rfind("ibr: error:", 0), 0u) << r.err;
    EXPECT_NE(r.err.find("memory budget"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
}

// Tiled height maps on a low-poly mesh ask for 512 subdivisions per face
// edge (372 faces: 97.5 million triangles, over 13 GiB): under `ulimit -v`
// the plan fits what the limit leaves, and says so (ctest runs this case
// alone as apps/displace_memory_cli_test, labelled slow).
TEST(DisplaceCli, TessellatedTruthUnderAnAddressSpaceLimitRendersOrIsRefused) {
  const fs::path out = test_support::TestOutputDir() / "truth.png";
  const auto r = RunCommand("sh -c \"ulimit -v 7812500 && exec " + IbrBinary() +
                            " --log-level warn displace --method tessellated" + Spot() +
                            " --tiling 64 --size 64 --frames 0 --out " + Quote(out) + "\"");
  ExpectRendersOrIsRefused(r, out);
  if (r.exit_code == 0) {
    EXPECT_NE(r.out.find("the memory budget"), std::string::npos) << r.out;
  }
  std::printf("%s%s", r.out.c_str(), r.err.c_str());
}

TEST(DisplaceCli, TessellatedTruthOverTheBudgetIsOneLine) {
  const fs::path out = test_support::TestOutputDir() / "never.png";
  const auto r = RunCommand(IbrBinary() +
                            " --log-level warn --memory-budget 32K displace --method tessellated" +
                            Spot() + " --tiling 64 --size 64 --frames 0 --out " + Quote(out));
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  ExpectRendersOrIsRefused(r, out);
  std::printf("%s", r.err.c_str());
}

// Mean absolute RGB difference over pixels both images cover.
double MeanColourDifference(const core::Image8& a, const core::Image8& b, int* both) {
  double sum = 0;
  *both = 0;
  for (size_t p = 0; p < a.pixel_count(); ++p) {
    if (a.data()[4 * p + 3] != 255 || b.data()[4 * p + 3] != 255) continue;
    ++*both;
    for (int k = 0; k < 3; ++k) sum += std::abs(a.data()[4 * p + k] - b.data()[4 * p + k]);
  }
  return *both > 0 ? sum / (3.0 * *both) : 1e9;
}

// Every method shades Spot with its texture where the mesh's uvs put it:
// its plain (--unlit) colours match the tessellated truth's (texture at the
// mesh's uvs) with --tiling 4, and a texture tiled 4x (--texture-tiling 4,
// the old behaviour of --tiling) does not. Unlit, because each method's
// normals differ (the truth's are its facets', the others' interpolate the
// base's vertex normals): the comparison is about where the texture lands.
TEST(DisplaceCli, EveryMethodShadesTheColourTextureAtTheMeshUvs) {
  const fs::path dir = test_support::TestOutputDir();
  // Seen from the front (the eyes), a 64-texel height map keeps the truth small.
  const std::string common = Spot() +
                             " --tiling 4 --texels 64 --size 128 --frames 0 --slices 24 "
                             "--azimuth 180 --elevation 10 --unlit";
  auto render = [&](const std::string& method, const std::string& extra) {
    const fs::path out = dir / fmt::format("{}{}.png", method, extra.size());
    const auto r = RunCommand(IbrBinary() + " displace --method " + method + common + extra +
                              " --out " + Quote(out));
    EXPECT_EQ(r.exit_code, 0) << method << "\n" << r.out << r.err;
    return r.exit_code == 0 ? core::ReadImage<uint8_t>(out) : core::Image8();
  };
  const core::Image8 truth = render("tessellated", "");
  ASSERT_FALSE(truth.empty());
  const core::Image8 tiled = render("tessellated", " --texture-tiling 4");
  int both = 0;
  const double wrong = MeanColourDifference(tiled, truth, &both);
  std::printf("texture tiled 4x vs truth: mean |dRGB| %.1f over %d pixels\n", wrong, both);
  for (const std::string method :
       {"slices-surface", "slices-orthogonal", "slices-screen", "ncs", "relief", "pom", "crm"}) {
    const core::Image8 image = render(method, "");
    if (image.empty()) continue;
    const double d = MeanColourDifference(image, truth, &both);
    std::printf("%s vs truth: mean |dRGB| %.1f over %d pixels\n", method.c_str(), d, both);
    EXPECT_GT(both, 2000) << method;
    EXPECT_LT(d, 0.5 * wrong) << method;
  }
}

// --texture is what colours the mesh: no line says "untextured" before it is
// drawn, and a displacement of the order of the mesh itself is warned about
// with its numbers (Spot is about 1.6 units across; 0.03 is not warned).
TEST(DisplaceCli, TextureIsNotCalledMissingAndAHugeDisplacementIsWarned) {
  const fs::path out = test_support::TestOutputDir() / "huge.png";
  const std::string mesh = " --mesh " + Quote(kReal / "spot_control_mesh.obj") + " --texture " +
                           Quote(kReal / "spot_texture.png") + " --up y";
  for (const auto& [amount, warned] : {std::pair{"0.03", false}, std::pair{"2", true}}) {
    SCOPED_TRACE(amount);
    const auto r =
        RunCommand(IbrBinary() + " displace --method relief" + mesh + " --max-displacement " +
                   amount + " --size 32 --frames 0 --out " + Quote(out));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err.find("untextured"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("no texture found"), std::string::npos) << r.err;
    const bool said =
        r.err.find("--max-displacement " + std::string(amount) + " is ") != std::string::npos &&
        r.err.find("% of the mesh's diagonal") != std::string::npos;
    EXPECT_EQ(said, warned) << r.err;
  }
}

// A user's closed mesh with poles: a UV-mapped capsule (v from pole to
// pole, a seam at u = 0 / 1) written as an exporter writes OBJ (v/vt/vn
// per corner), with a 16-bit PNG height map. NCS covers what the
// tessellated truth covers -- no hole at the poles, none along the seam --
// from the side, from above a pole and in between, at a displacement of
// 10 % of the radius (the range docs/guide/displacement.md states).
TEST(DisplaceCli, NcsOnAUserCapsuleWithPolesMatchesTheTruth) {
  const fs::path dir = test_support::TestOutputDir();
  const core::TriangleMesh capsule = core::MakeCapsule(0.5f, 1.0f, 12, 4, 48);
  {
    std::ofstream obj(dir / "capsule.obj");
    obj << "# a UV capsule, radius 0.5, 2 tall\n";
    for (const glm::vec3& p : capsule.positions) obj << fmt::format("v {} {} {}\n", p.x, p.y, p.z);
    for (const glm::vec2& t : capsule.uvs) obj << fmt::format("vt {} {}\n", t.x, t.y);
    for (const glm::vec3& n : capsule.normals) obj << fmt::format("vn {} {} {}\n", n.x, n.y, n.z);
    for (size_t i = 0; i < capsule.indices.size(); i += 3) {
      obj << "f";
      for (int k = 0; k < 3; ++k) obj << fmt::format(" {0}/{0}/{0}", capsule.indices[i + k] + 1);
      obj << "\n";
    }
  }
  core::Image<uint16_t> height(64, 64, 1);
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      const double h =
          0.5 + 0.5 * std::sin(2 * M_PI * 4 * x / 64) * std::sin(2 * M_PI * 4 * y / 64);
      height.at(x, y) = static_cast<uint16_t>(std::lround(65535 * h));
    }
  }
  core::WriteImage(dir / "height.png", height);
  for (const char* elevation : {"10", "60", "90"}) {
    SCOPED_TRACE(elevation);
    const auto r =
        RunCommand(IbrBinary() + " displace --method ncs --mesh " + Quote(dir / "capsule.obj") +
                   " --height-map " + Quote(dir / "height.png") +
                   " --max-displacement 0.05 --tiling 1 --size 160 --frames 0 "
                   "--compare --elevation " +
                   elevation + " --out " + Quote(dir / "capsule.png"));
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    const size_t at = r.out.find("coverage IoU ");
    ASSERT_NE(at, std::string::npos) << r.out;
    const double iou = std::stod(r.out.substr(at + 13));
    std::printf("capsule, elevation %s: ncs coverage IoU %.4f\n", elevation, iou);
    EXPECT_GE(iou, 0.98) << r.out;
  }
}

TEST(DisplaceCli, BackgroundMakesTheImageOpaque) {
  const fs::path out = test_support::TestOutputDir() / "opaque.png";
  const auto r = RunCommand(IbrBinary() + " displace --method relief" + Spot() +
                            " --size 64 --frames 0 --background 10,20,30 --out " + Quote(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const core::Image8 c = core::ReadImage<uint8_t>(out);
  for (size_t p = 0; p < c.pixel_count(); ++p) ASSERT_EQ(c.data()[4 * p + 3], 255) << p;
  EXPECT_EQ(c.at(0, 0, 0), 10);  // a corner is background
  EXPECT_EQ(c.at(0, 0, 1), 20);
  EXPECT_EQ(c.at(0, 0, 2), 30);
}

TEST(DisplaceCli, BadCameraOptionsAreOneLine) {
  const fs::path out = test_support::TestOutputDir() / "never.png";
  for (const std::string bad :
       {"", " --background 1,2", " --background 1,2,300", " --fov 0", " --distance -1"}) {
    const std::string up = bad.empty() ? "w" : "y";
    const auto r = RunCommand(IbrBinary() + " displace --method relief" + Spot(up) +
                              " --size 64 --frames 0" + bad + " --out " + Quote(out));
    EXPECT_EQ(r.exit_code, 1) << bad << "\n" << r.out << r.err;
    EXPECT_EQ(CountLines(r.err), 1) << bad << "\n" << r.err;
    EXPECT_FALSE(fs::exists(out)) << bad;
  }
}

}  // namespace
