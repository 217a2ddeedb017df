// The on-disk program cache (render/gl/program_binary_cache.h): a program
// loaded from a binary draws the same image as a compiled one; corrupt,
// truncated or foreign files and another driver fall back to compiling.
// Runs with Mesa's disk cache enabled (tests/render/CMakeLists.txt), which
// Mesa needs to offer its program binary format.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <vector>

#include "core/mesh.h"
#include "core/projection.h"
#include "render/gl/program_binary_cache.h"
#include "render/gl/shader_program.h"
#include "render/passes/mesh_pass.h"
#include "tests/support/gl_test.h"

namespace render {
namespace {

namespace fs = std::filesystem;

class ProgramCacheTest : public test_support::GlTest {
 protected:
  // A shaded sphere in perspective: the mesh program with lighting, normals
  // and every view uniform, so a wrongly restored program shows.
  Frame Draw(ProgramCache& programs) {
    static const core::TriangleMesh mesh = core::MakeSphere(1.0f, 32, 64);
    const GpuMesh sphere(mesh);
    ViewSetup view;
    view.cam_from_world = core::CamFromWorldLookAt({1.5, 1.0, 3.5}, {0, 0, 0}, {0, 1, 0});
    view.clip_from_cam = core::ClipFromCamPerspective(120.0, 120.0, kSize / 2.0, kSize / 2.0, kSize,
                                                      kSize, 0.5, 10.0);
    MeshPassOptions options;
    options.base_color = {0.9f, 0.5f, 0.2f, 1.0f};
    return RenderMesh(programs, sphere, view, kSize, kSize, options);
  }

  static std::vector<fs::path> Files(const fs::path& dir) {
    std::vector<fs::path> files;
    if (!fs::exists(dir)) return files;
    for (const auto& e : fs::directory_iterator(dir)) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    return files;
  }

  static std::string ReadAll(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  static void WriteAll(const fs::path& p, const std::string& bytes) {
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }

  // The cold run: compiles, stores one binary per program, returns the image.
  Frame Cold(const fs::path& dir) {
    ProgramCache cold(ShaderSources::Embedded(), dir);
    const Frame frame = Draw(cold);
    EXPECT_TRUE(cold.disk()->available()) << "the driver offers no program binary format";
    EXPECT_EQ(cold.disk()->stats().hits, 0);
    EXPECT_GE(cold.disk()->stats().misses, 1);
    EXPECT_EQ(cold.disk()->stats().stored, static_cast<int>(cold.size()));
    EXPECT_EQ(Files(dir).size(), cold.size());
    return frame;
  }

  static constexpr int kSize = 96;
};

void ExpectSameImage(const Frame& a, const Frame& b) {
  ASSERT_EQ(a.color.width(), b.color.width());
  EXPECT_EQ(a.color.values(), b.color.values());
  EXPECT_EQ(a.depth.values(), b.depth.values());
  EXPECT_EQ(a.normal.values(), b.normal.values());
  int covered = 0;
  for (int y = 0; y < a.color.height(); ++y)
    for (int x = 0; x < a.color.width(); ++x) covered += a.Covered(x, y);
  EXPECT_GT(covered, 1000);  // the sphere is in the picture
}

TEST_F(ProgramCacheTest, ProgramFromTheCacheDrawsTheSameImageAsACompiledOne) {
  const fs::path dir = test_support::TestOutputDir() / "cache";
  const Frame compiled = Cold(dir);
  ProgramCache warm(ShaderSources::Embedded(), dir);
  const Frame loaded = Draw(warm);
  EXPECT_EQ(warm.disk()->stats().hits, static_cast<int>(warm.size()));
  EXPECT_EQ(warm.disk()->stats().misses + warm.disk()->stats().rejected, 0);
  EXPECT_EQ(warm.disk()->stats().stored, 0);
  ExpectSameImage(compiled, loaded);
  // And the same as the cache without a disk layer (the fixture's).
  ExpectSameImage(compiled, Draw(programs()));
  EXPECT_NO_GL_ERROR();
}

TEST_F(ProgramCacheTest, CorruptOrTruncatedFilesFallBackToCompiling) {
  const fs::path dir = test_support::TestOutputDir() / "cache";
  const Frame compiled = Cold(dir);
  const std::vector<fs::path> files = Files(dir);
  ASSERT_FALSE(files.empty());
  const std::string good = ReadAll(files[0]);
  ASSERT_GT(good.size(), 64u);
  // Each damage in turn: a flipped byte inside the binary (the checksum
  // catches it), a truncation, an empty file, garbage of the right length,
  // trailing bytes.
  std::string flipped = good;
  flipped[good.size() - 20] = static_cast<char>(flipped[good.size() - 20] ^ 0x5a);
  const std::vector<std::pair<const char*, std::string>> damages = {
      {"flipped byte", flipped},
      {"truncated", good.substr(0, good.size() / 2)},
      {"empty", ""},
      {"garbage", std::string(good.size(), '\x7f')},
      {"trailing bytes", good + "xyz"}};
  for (const auto& [what, bytes] : damages) {
    SCOPED_TRACE(what);
    for (const fs::path& f : files) WriteAll(f, bytes);
    ProgramCache damaged(ShaderSources::Embedded(), dir);
    const Frame frame = Draw(damaged);
    EXPECT_EQ(damaged.disk()->stats().hits, 0);
    EXPECT_EQ(damaged.disk()->stats().rejected, static_cast<int>(files.size()));
    // Compiled again and the files rewritten: the next run loads them.
    EXPECT_EQ(damaged.disk()->stats().stored, static_cast<int>(files.size()));
    ExpectSameImage(compiled, frame);
    ProgramCache repaired(ShaderSources::Embedded(), dir);
    ExpectSameImage(compiled, Draw(repaired));
    EXPECT_EQ(repaired.disk()->stats().hits, static_cast<int>(files.size()));
  }
  EXPECT_NO_GL_ERROR();
}

TEST_F(ProgramCacheTest, AnotherDriverOrSourceMisses) {
  const fs::path dir = test_support::TestOutputDir() / "cache";
  const Frame compiled = Cold(dir);

  // Another driver string: another file name, so a miss, compiled and stored
  // beside the first.
  ProgramCache other(ShaderSources::Embedded(), dir);
  other.disk()->set_driver_for_testing("Some Vendor|Other GPU|4.6 9.9|4.60");
  const Frame frame = Draw(other);
  EXPECT_EQ(other.disk()->stats().hits, 0);
  EXPECT_EQ(other.disk()->stats().misses, static_cast<int>(other.size()));
  EXPECT_EQ(Files(dir).size(), 2 * other.size());
  ExpectSameImage(compiled, frame);

  // A file copied under another driver's name (a hash collision, or a cache
  // carried between machines) holds the other key: rejected, never handed to
  // the driver. Likewise a changed source (one more define) misses.
  const ShaderSources sources({{"full.vert.glsl", R"(#version 330 core
void main() {
  vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
)"},
                               {"flat.frag.glsl", R"(#version 330 core
out vec4 o_color;
void main() { o_color = vec4(0.25, 0.5, float(LEVEL) / 255.0, 1.0); }
)"}});
  const ProgramDesc desc{"full.vert.glsl", "", "flat.frag.glsl", "", {"LEVEL 7"}};
  const ProgramSources pre = PreprocessProgram(sources, desc);
  const std::string key = pre.CacheKey(desc);
  ProgramBinaryCache here(dir / "direct");
  here.Store(key, BuildProgram(pre, desc, /*retrievable=*/true));
  EXPECT_EQ(here.stats().stored, 1);
  EXPECT_TRUE(here.Load(key).has_value());
  ProgramBinaryCache elsewhere(dir / "direct");
  elsewhere.set_driver_for_testing("Some Vendor|Other GPU|4.6 9.9|4.60");
  ASSERT_NE(elsewhere.PathFor(key), here.PathFor(key));
  fs::copy_file(here.PathFor(key), elsewhere.PathFor(key));
  EXPECT_FALSE(elsewhere.Load(key).has_value());
  EXPECT_EQ(elsewhere.stats().rejected, 1);
  ProgramDesc desc2 = desc;
  desc2.defines.push_back("SOMETHING_ELSE");
  EXPECT_FALSE(here.Load(PreprocessProgram(sources, desc2).CacheKey(desc2)).has_value());
  EXPECT_EQ(here.stats().misses, 1);
  EXPECT_NO_GL_ERROR();
}

TEST(ShaderCacheDirTest, EnvironmentPicksTheFolder) {
  // Saved and restored: the variables this test changes.
  std::vector<std::pair<const char*, std::optional<std::string>>> saved;
  for (const char* name : {"IBR_CACHE_DIR", "XDG_CACHE_HOME", "HOME"}) {
    const char* v = std::getenv(name);
    saved.emplace_back(name, v ? std::optional<std::string>(v) : std::nullopt);
  }
  // Paths only composed, never created: under the temporary folder.
  const fs::path base = fs::temp_directory_path() / "ibr_cache_dir_test";
  ::setenv("IBR_CACHE_DIR", (base / "some" / "where").c_str(), 1);
  EXPECT_EQ(DefaultShaderCacheDir(), base / "some" / "where");
  ::setenv("IBR_CACHE_DIR", "off", 1);
  EXPECT_TRUE(DefaultShaderCacheDir().empty());
  ::unsetenv("IBR_CACHE_DIR");
  ::setenv("XDG_CACHE_HOME", (base / "xdg").c_str(), 1);
  EXPECT_EQ(DefaultShaderCacheDir(), base / "xdg" / "ibr");
  ::unsetenv("XDG_CACHE_HOME");
  ::setenv("HOME", (base / "home").c_str(), 1);
  EXPECT_EQ(DefaultShaderCacheDir(), base / "home" / ".cache" / "ibr");
  for (const auto& [name, value] : saved) {
    if (value) {
      ::setenv(name, value->c_str(), 1);
    } else {
      ::unsetenv(name);
    }
  }
}

}  // namespace
}  // namespace render
