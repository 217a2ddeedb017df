// The typed-program rule (docs/decisions/typed-programs.md): outside
// render/gl/, no C++ source sets a uniform by name. Uniforms are set only
// through Uniform<T> handles of a typed struct that Program::Typed builds once
// per linked program (render/gl/uniform.h). The scan covers every .cc/.h of
// the checkout except tests/ (tests drive the facility and their own test
// shaders directly) and build trees; it flags
//   - a by-name set:          x.Set("u_x", v), x->Set("u_x", v) (GLSL uniforms are u_*)
//   - any Set(...) on a variable declared as a Program (a name held in a string)
//   - a raw GL uniform call:  glUniform*, glProgramUniform*
//   - a by-name lookup:       program.Uniform("u_x") (then set by location)
//   - a handle made and used at once: Uniform<float>(p, "u_x").Set(v)
// And the GL-call rule (ARCHITECTURE.md, layers): outside render/, no C++
// source makes a raw GL call (glAnything(...)); GL work goes through
// render/gl's plumbing and render/passes' passes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

struct Finding {
  std::string file;
  int line = 0;
  std::string rule;
  std::string text;
};

// The line without its // comment (string literals containing "//" do not
// occur in the patterns we look for).
std::string StripComment(const std::string& line) {
  const size_t at = line.find("//");
  return at == std::string::npos ? line : line.substr(0, at);
}

// Every violation in one file's text.
std::vector<Finding> ScanText(const std::string& file, const std::string& text) {
  static const std::regex by_name(R"((\.|->)\s*Set\s*\(\s*"u_)");
  static const std::regex raw_gl(R"(\bgl(Program)?Uniform(Matrix)?[1-4])");
  static const std::regex lookup(R"((\.|->)\s*Uniform\s*\()");
  static const std::regex one_shot(
      R"(\bUniform(Array)?\s*<[^;]*>\s*[({][^;]*[)}]\s*\.\s*Set\s*\()");
  static const std::regex program_decl(R"(\bProgram\s*[&*]+\s*(\w+)|\bProgram\s+(\w+)\s*[=({;])");
  std::vector<std::string> lines;
  {
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line)) lines.push_back(StripComment(line));
  }
  // Names declared as a Program anywhere in the file.
  std::set<std::string> programs;
  for (const std::string& line : lines) {
    for (auto it = std::sregex_iterator(line.begin(), line.end(), program_decl);
         it != std::sregex_iterator(); ++it) {
      programs.insert((*it)[1].matched ? (*it)[1].str() : (*it)[2].str());
    }
  }
  std::vector<Finding> found;
  for (size_t i = 0; i < lines.size(); ++i) {
    const std::string& line = lines[i];
    const int n = static_cast<int>(i) + 1;
    if (std::regex_search(line, by_name))
      found.push_back({file, n, "by-name Set(\"u_...\")", line});
    if (std::regex_search(line, raw_gl)) found.push_back({file, n, "raw glUniform call", line});
    if (std::regex_search(line, lookup)) {
      found.push_back({file, n, "by-name location lookup", line});
    }
    if (std::regex_search(line, one_shot)) {
      found.push_back({file, n, "handle made and set at once", line});
    }
    for (const std::string& p : programs) {
      const std::regex set_on_program("\\b" + p + R"(\s*(\.|->)\s*Set\s*\()");
      if (std::regex_search(line, set_on_program)) {
        found.push_back({file, n, "Set on Program '" + p + "'", line});
      }
    }
  }
  return found;
}

std::string Describe(const std::vector<Finding>& found) {
  std::string out;
  for (const Finding& f : found) {
    out += f.file + ":" + std::to_string(f.line) + ": " + f.rule + ": " + f.text + "\n";
  }
  return out;
}

struct SourceFile {
  std::string path;  // relative to the checkout, '/'-separated
  std::string text;
};

// Every C++ source of the checkout at `root`, except in dot folders, the
// top-level tests/ and build trees, and the folders in `skip`.
std::vector<SourceFile> SourcesOutside(const fs::path& root, const std::vector<fs::path>& skip) {
  std::vector<SourceFile> sources;
  for (auto it = fs::recursive_directory_iterator(root); it != fs::recursive_directory_iterator();
       ++it) {
    const fs::path& path = it->path();
    const std::string name = path.filename().string();
    if (it->is_directory()) {
      const bool top = path.parent_path() == root;
      if (name.starts_with(".") || (top && (name == "tests" || name.starts_with("build"))) ||
          std::find(skip.begin(), skip.end(), path) != skip.end()) {
        it.disable_recursion_pending();
      }
      continue;
    }
    const std::string ext = path.extension().string();
    if (ext != ".cc" && ext != ".h" && ext != ".cpp" && ext != ".hpp") continue;
    std::ifstream in(path, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    sources.push_back({fs::relative(path, root).generic_string(), text.str()});
  }
  return sources;
}

// The scanner itself: each rule fires on its pattern and not on lookalikes.
TEST(UniformRule, TheScannerCatchesEveryForm) {
  const auto count = [](const std::string& text) { return ScanText("x.cc", text).size(); };
  EXPECT_EQ(count(R"(program.Set("u_twist", 1.0f);)"), 1u);
  EXPECT_EQ(count(R"(program->Set( "u_twist", 1.0f);)"), 1u);
  EXPECT_EQ(count("const render::Program& pass = cache.Get(d);\npass.Set(names.map, 2);"), 1u);
  EXPECT_EQ(count("for (const Program* p : list) p->Set(name, 2);"), 1u);
  EXPECT_EQ(count("glUniform1f(loc, 2.0f);"), 1u);
  EXPECT_EQ(count("glProgramUniformMatrix4fv(id, loc, 1, GL_FALSE, m);"), 1u);
  EXPECT_EQ(count(R"(const GLint loc = pass.Uniform("u_slice_plane");)"), 1u);
  EXPECT_EQ(count(R"(render::Uniform<float>(program, "u_x").Set(2.0f);)"), 1u);
  // What the typed pattern and other Set methods look like: no finding.
  EXPECT_EQ(count(R"(  : twist(p, "u_twist") {})"), 0u);
  EXPECT_EQ(count("const auto& u = program.Typed<DeformUniforms>();\nu.twist.Set(1.0f);"), 0u);
  EXPECT_EQ(count(R"(settings.Set("method", f.method, "--method");)"), 0u);
  EXPECT_EQ(count(R"(// program.Set("u_x", 1) in a comment)"), 0u);
}

TEST(UniformRule, NoUniformIsSetByNameOutsideRenderGl) {
  const char* source = std::getenv("IBR_SOURCE_DIR");
  ASSERT_NE(source, nullptr) << "IBR_SOURCE_DIR (set by ctest) names the checkout";
  const fs::path root(source);
  std::vector<Finding> found;
  int files = 0;
  for (const SourceFile& f : SourcesOutside(root, {root / "render" / "gl"})) {
    const std::vector<Finding> here = ScanText(f.path, f.text);
    found.insert(found.end(), here.begin(), here.end());
    ++files;
  }
  std::printf("scanned %d source files outside tests/ and render/gl/: %zu by-name uniform sets\n",
              files, found.size());
  // A partial scan would pass vacuously: the library folders alone hold more.
  EXPECT_GT(files, 100);
  EXPECT_TRUE(found.empty()) << "set uniforms through a typed struct of Uniform<T> handles "
                                "(render/gl/uniform.h), not by name:\n"
                             << Describe(found);
}

// Every raw GL call (glName( with an upper-case letter after "gl") in one
// file's text, comments left out.
std::vector<Finding> ScanGlCalls(const std::string& file, const std::string& text) {
  static const std::regex gl_call(R"(\bgl[A-Z][A-Za-z0-9]*\s*\()");
  std::vector<Finding> found;
  std::istringstream in(text);
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    const std::string code = StripComment(line);
    if (std::regex_search(code, gl_call)) found.push_back({file, n, "raw GL call", code});
  }
  return found;
}

TEST(GlCallRule, TheScannerCatchesGlCallsOnly) {
  const auto count = [](const std::string& text) { return ScanGlCalls("x.cc", text).size(); };
  EXPECT_EQ(count("glFinish();"), 1u);
  EXPECT_EQ(count("  glTextureParameteri(t.id(), GL_TEXTURE_WRAP_S, GL_REPEAT);"), 1u);
  EXPECT_EQ(count("x = glGetString (GL_RENDERER);"), 1u);
  EXPECT_EQ(count("glFinish();\nglFlush();"), 2u);
  // Wrappers, GL types and constants, comments: no finding.
  EXPECT_EQ(count("render::WaitForGpu();"), 0u);
  EXPECT_EQ(count("const GLuint texture = target.color(0).id();"), 0u);
  EXPECT_EQ(count("t.internal_format = GL_RGBA8;"), 0u);
  EXPECT_EQ(count("// wall clock plus glFinish() after the frame"), 0u);
  EXPECT_EQ(count("auto glow(1.0f); bool global(); myglFinish();"), 0u);
}

TEST(GlCallRule, NoGlCallOutsideRender) {
  const char* source = std::getenv("IBR_SOURCE_DIR");
  ASSERT_NE(source, nullptr) << "IBR_SOURCE_DIR (set by ctest) names the checkout";
  const fs::path root(source);
  std::vector<Finding> found;
  int files = 0;
  for (const SourceFile& f : SourcesOutside(root, {root / "render"})) {
    const std::vector<Finding> here = ScanGlCalls(f.path, f.text);
    ++files;
    found.insert(found.end(), here.begin(), here.end());
  }
  std::printf("scanned %d source files outside tests/ and render/: %zu raw GL calls\n", files,
              found.size());
  EXPECT_GT(files, 100);  // a partial scan would pass vacuously
  EXPECT_TRUE(found.empty()) << "call GL through render/gl or render/passes:\n" << Describe(found);
}

}  // namespace
