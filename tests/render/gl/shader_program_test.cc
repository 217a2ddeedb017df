#include "render/gl/shader_program.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "render/gl/render_target.h"
#include "tests/support/gl_test.h"

namespace render {
namespace {

const char* kVertex = R"(#version 330 core
void main() {
  vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
)";

ShaderSources TestSources() {
  return ShaderSources({
      {"full.vert.glsl", kVertex},
      {"variant.frag.glsl", R"(#version 330 core
out vec4 o_color;
void main() {
#ifdef RED
  o_color = vec4(1.0, 0.0, 0.0, 1.0);
#else
  o_color = vec4(0.0, 1.0, 0.0, 1.0);
#endif
#ifdef LEVEL
  o_color.b = float(LEVEL) / 255.0;
#endif
}
)"},
      // Line 4 is broken.
      {"broken.frag.glsl",
       "#version 330 core\nout vec4 o_color;\nvoid main() {\n  o_color = undefined_thing;\n}\n"},
      // Line 3 of the chunk is broken.
      {"bad_chunk.glsl",
       "// a chunk\nfloat good() { return 1.0; }\nfloat bad() { return nonsense; }\n"},
      {"uses_bad_chunk.frag.glsl",
       "#version 330 core\n#include \"bad_chunk.glsl\"\nout vec4 o_color;\nvoid main() { o_color = "
       "vec4(good()); }\n"},
      // The chunk is fine; line 6 of the root (after the include) is broken.
      {"good_chunk.glsl", "float helper() { return 0.5; }\n"},
      {"other_chunk.glsl", "#include \"good_chunk.glsl\"\nfloat other() { return helper(); }\n"},
      {"error_after_include.frag.glsl",
       "#version 330 core\n#include \"good_chunk.glsl\"\n#include \"other_chunk.glsl\"\nout vec4 "
       "o_color;\n"
       "void main() {\n  o_color = vec4(missing_after);\n}\n"},
      {"twice.frag.glsl",
       "#version 330 core\n#include \"good_chunk.glsl\"\n#include \"other_chunk.glsl\"\nout vec4 "
       "o_color;\n"
       "void main() { o_color = vec4(helper() + other()); }\n"},
      {"missing.frag.glsl", "#version 330 core\n#include \"nope.glsl\"\nvoid main() {}\n"},
      {"cycle_a.glsl", "#include \"cycle_b.glsl\"\n"},
      {"cycle_b.glsl", "#include \"cycle_a.glsl\"\n"},
      {"no_version.frag.glsl", "void main() {}\n"},
  });
}

std::string BuildError(const ShaderSources& sources, const ProgramDesc& desc) {
  try {
    BuildProgram(sources, desc);
  } catch (const core::InputError& e) {
    return e.what();
  }
  return "";
}

class ShaderProgramTest : public test_support::GlTest {};

TEST_F(ShaderProgramTest, CompileErrorNamesFileAndLine) {
  const ShaderSources sources = TestSources();
  const std::string error =
      BuildError(sources, {.vertex = "full.vert.glsl", .fragment = "broken.frag.glsl"});
  EXPECT_NE(error.find("broken.frag.glsl:4"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << "must be one line: " << error;
}

TEST_F(ShaderProgramTest, ErrorInIncludedChunkNamesTheChunk) {
  const ShaderSources sources = TestSources();
  const std::string error =
      BuildError(sources, {.vertex = "full.vert.glsl", .fragment = "uses_bad_chunk.frag.glsl"});
  EXPECT_NE(error.find("bad_chunk.glsl:3"), std::string::npos) << error;
}

TEST_F(ShaderProgramTest, LineNumbersResumeAfterIncludes) {
  const ShaderSources sources = TestSources();
  const std::string error = BuildError(
      sources, {.vertex = "full.vert.glsl", .fragment = "error_after_include.frag.glsl"});
  EXPECT_NE(error.find("error_after_include.frag.glsl:6"), std::string::npos) << error;
}

TEST_F(ShaderProgramTest, DefinesAreAppliedAndIncludesResolvedOnce) {
  const ShaderSources sources = TestSources();
  const PreprocessedSource pre = PreprocessShader(sources, "twice.frag.glsl", {"RED", "LEVEL 3"});
  EXPECT_EQ(pre.text.rfind("#version 330 core\n#define RED\n#define LEVEL 3\n", 0), 0u) << pre.text;
  ASSERT_EQ(pre.files.size(), 3u);  // root, good_chunk (once), other_chunk
  EXPECT_EQ(pre.files[1], "good_chunk.glsl");
  EXPECT_NO_THROW(
      BuildProgram(sources, {.vertex = "full.vert.glsl", .fragment = "twice.frag.glsl"}));
}

TEST_F(ShaderProgramTest, BadSourcesAreInputErrors) {
  const ShaderSources sources = TestSources();
  EXPECT_THROW(PreprocessShader(sources, "missing.frag.glsl", {}), core::InputError);
  EXPECT_THROW(PreprocessShader(sources, "cycle_a.glsl", {}), core::InputError);
  EXPECT_THROW(PreprocessShader(sources, "no_version.frag.glsl", {}), core::InputError);
  EXPECT_THROW(PreprocessShader(sources, "nonexistent.glsl", {}), core::InputError);
  EXPECT_THROW(PreprocessShader(sources, "twice.frag.glsl", {"1BAD"}), core::InputError);
}

TEST_F(ShaderProgramTest, VariantDefineChangesWhatIsDrawn) {
  const ShaderSources sources = TestSources();
  ProgramCache cache(sources);
  RenderTarget target({4, 4, {GL_RGBA8}, false});
  VertexArray vao = VertexArray::Create();
  auto draw = [&](std::vector<std::string> defines) {
    const Program& p = cache.Get(
        {.vertex = "full.vert.glsl", .fragment = "variant.frag.glsl", .defines = defines});
    target.Bind();
    p.Use();
    glBindVertexArray(vao.id());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    return target.ReadColor8();
  };
  const core::Image8 green = draw({});
  const core::Image8 red = draw({"RED"});
  const core::Image8 red_level = draw({"LEVEL 7", "RED"});
  EXPECT_EQ(green.at(1, 1, 0), 0);
  EXPECT_EQ(green.at(1, 1, 1), 255);
  EXPECT_EQ(red.at(1, 1, 0), 255);
  EXPECT_EQ(red.at(1, 1, 1), 0);
  EXPECT_EQ(red_level.at(2, 2, 2), 7);
  EXPECT_EQ(cache.size(), 3u);
  // Same defines in another order: the same cached program.
  const Program* a = &cache.Get(
      {.vertex = "full.vert.glsl", .fragment = "variant.frag.glsl", .defines = {"RED", "LEVEL 7"}});
  EXPECT_EQ(cache.size(), 3u);
  EXPECT_EQ(a, &cache.Get({.vertex = "full.vert.glsl",
                           .fragment = "variant.frag.glsl",
                           .defines = {"LEVEL 7", "RED"}}));
}

TEST(ShaderLog, TranslatesMesaAndNvidiaReferences) {
  const std::vector<std::string> files = {"root.glsl", "chunk.glsl"};
  EXPECT_EQ(TranslateShaderLog("1:12(3): error: x\n0:2(1): error: y", files),
            "chunk.glsl:12(3): error: x\nroot.glsl:2(1): error: y");
  EXPECT_EQ(TranslateShaderLog("0(7) : error C1008: z", files), "root.glsl:7 : error C1008: z");
}

TEST_F(ShaderProgramTest, EveryEmbeddedStageFilePreprocesses) {
  const ShaderSources& embedded = ShaderSources::Embedded();
  ASSERT_FALSE(embedded.Names().empty());
  for (const auto& name : embedded.Names()) {
    const bool is_stage = name.ends_with(".vert.glsl") || name.ends_with(".frag.glsl") ||
                          name.ends_with(".geom.glsl") || name.ends_with(".comp.glsl");
    if (is_stage) {
      EXPECT_NO_THROW(PreprocessShader(embedded, name, {})) << name;
    }
  }
}

}  // namespace
}  // namespace render
