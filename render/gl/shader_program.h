// Shader programs from the .glsl files in shaders/ (Magnum-style variants):
//  - a program is a set of stage files plus a list of #defines, inserted right
//    after the #version line, so a scene compiles only the effects it uses;
//  - `#include "chunk.glsl"` lines are resolved at load (once per program), so
//    the slicing and ray cores are shared GLSL, never copies;
//  - every file gets a GLSL source-string number through `#line`, and compile
//    logs are rewritten from "N:LINE(COL)" to "file.glsl:LINE(COL)";
//  - ProgramCache keys programs by file set + defines.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "render/gl/handles.h"

namespace render {

// Named GLSL sources: the embedded shaders/ folder, or any set a test makes.
class ShaderSources {
 public:
  explicit ShaderSources(std::map<std::string, std::string> files) : files_(std::move(files)) {}
  // The files embedded from shaders/ at build time.
  static const ShaderSources& Embedded();

  // nullptr when there is no such file.
  const std::string* Find(const std::string& name) const;
  std::vector<std::string> Names() const;

 private:
  std::map<std::string, std::string> files_;
};

struct ProgramDesc {
  // File names relative to shaders/; empty = stage absent.
  std::string vertex;
  std::string geometry;
  std::string fragment;
  std::string compute;
  // "NAME" or "NAME VALUE"; NAME must be a GLSL identifier.
  std::vector<std::string> defines;

  // Canonical cache key: stages in fixed order, defines sorted.
  std::string Key() const;
  void Check() const;
};

// A stage's source after define insertion and include resolution.
struct PreprocessedSource {
  std::string text;
  // files[i] is the file behind GLSL source-string number i.
  std::vector<std::string> files;
};

// Throws core::InputError for a missing file, a missing #version, a
// malformed #include, an include cycle or a bad define.
PreprocessedSource PreprocessShader(const ShaderSources& sources, const std::string& file,
                                    const std::vector<std::string>& defines);

// Rewrites "N:LINE(COL)" (Mesa) and "N(LINE)" (NVIDIA) source references in
// a compiler log into "file:LINE(COL)".
std::string TranslateShaderLog(const std::string& log, const std::vector<std::string>& files);

// Compiles and links; throws core::InputError whose message names the file
// and line of the first error (compile) or the stage files (link).
Program BuildProgram(const ShaderSources& sources, const ProgramDesc& desc);

// Programs by key. References stay valid for the cache's lifetime. Needs a
// current context for Get(); one cache per context.
class ProgramCache {
 public:
  explicit ProgramCache(const ShaderSources& sources = ShaderSources::Embedded())
      : sources_(&sources) {}
  const Program& Get(const ProgramDesc& desc);
  size_t size() const { return programs_.size(); }
  // Programs compiled by this cache, per stage file (a program counts once for
  // each of its stage files): what a scene made the cache build.
  const std::map<std::string, int>& compiled_by_file() const { return compiled_by_file_; }

 private:
  const ShaderSources* sources_;
  std::map<std::string, int> compiled_by_file_;
  std::unordered_map<std::string, std::unique_ptr<Program>> programs_;
};

}  // namespace render
