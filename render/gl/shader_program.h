// Shader programs from the .glsl files in shaders/ (Magnum-style variants):
//  - a program is a set of stage files plus a list of #defines, inserted right
//    after the #version line, so a scene compiles only the effects it uses;
//  - `#include "chunk.glsl"` lines are resolved at load (once per program), so
//    the slicing and ray cores are shared GLSL, never copies;
//  - every file gets a GLSL source-string number through `#line`, and compile
//    logs are rewritten from "N:LINE(COL)" to "file.glsl:LINE(COL)";
//  - ProgramCache keys programs by file set + defines, and keeps linked
//    programs between runs when given a directory (program_binary_cache.h).
#pragma once

#include <filesystem>
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

// Every stage of `desc`, preprocessed (vertex, geometry, fragment; or compute).
struct ProgramSources {
  struct Stage {
    GLenum type;
    std::string file;
    PreprocessedSource source;
  };
  std::vector<Stage> stages;
  // desc.Key() and every stage's full text: what a compiled program depends
  // on besides the driver (the key of the on-disk cache).
  std::string CacheKey(const ProgramDesc& desc) const;
};
ProgramSources PreprocessProgram(const ShaderSources& sources, const ProgramDesc& desc);

// Compiles and links; throws core::InputError whose message names the file
// and line of the first error (compile) or the stage files (link).
// `retrievable` asks the driver to keep the binary (glGetProgramBinary).
Program BuildProgram(const ProgramSources& sources, const ProgramDesc& desc,
                     bool retrievable = false);
Program BuildProgram(const ShaderSources& sources, const ProgramDesc& desc);

class ProgramBinaryCache;

// Programs by key. References stay valid for the cache's lifetime. Needs a
// current context for Get(); one cache per context. With a `disk_dir`
// (default: the process's ShaderCacheDir(), empty unless the command line
// enabled it) a program is first looked up among the binaries of earlier runs
// and stored there after compiling; any miss or bad file compiles.
class ProgramCache {
 public:
  explicit ProgramCache(const ShaderSources& sources = ShaderSources::Embedded());
  ProgramCache(const ShaderSources& sources, const std::filesystem::path& disk_dir);
  ~ProgramCache();
  ProgramCache(const ProgramCache&) = delete;
  ProgramCache& operator=(const ProgramCache&) = delete;
  const Program& Get(const ProgramDesc& desc);
  size_t size() const { return programs_.size(); }
  // The on-disk layer (nullptr: none).
  ProgramBinaryCache* disk() { return disk_.get(); }
  // Programs built by this cache (compiled, or loaded from the disk layer),
  // per stage file (a program counts once for each of its stage files): what a
  // scene made the cache build.
  const std::map<std::string, int>& compiled_by_file() const { return compiled_by_file_; }

 private:
  const ShaderSources* sources_;
  std::unique_ptr<ProgramBinaryCache> disk_;
  std::map<std::string, int> compiled_by_file_;
  std::unordered_map<std::string, std::unique_ptr<Program>> programs_;
};

}  // namespace render
