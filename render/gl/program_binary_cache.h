// Linked programs kept between runs (issue 12, "first image fast").
//
// Two layers, both under one directory that is ibr's own (never a user's
// input; clearing it only costs the next run its compile time):
//  - `programs/`: our program binaries (glGetProgramBinary / glProgramBinary,
//    ARB_get_program_binary), one file per program, keyed by a hash of
//    everything the binary depends on: the preprocessed source of every stage
//    (defines and includes resolved), the program's key, and the driver
//    (GL_VENDOR, GL_RENDERER, GL_VERSION, GL_SHADING_LANGUAGE_VERSION). The
//    file holds that whole key text too, and a checksum of the binary: a file
//    whose key differs (a hash collision, another driver), that is truncated
//    or corrupt, or that the driver refuses (glProgramBinary's link status)
//    is a miss, and the program is compiled and the file rewritten
//    (core::AtomicWrite). NVIDIA's EGL driver offers binary formats; Mesa
//    offers one (its serialized NIR) only while its disk cache is enabled.
//  - `mesa/`: Mesa's own on-disk shader cache (MESA_SHADER_CACHE_DIR), which
//    on llvmpipe also keeps the LLVM-compiled code of each shader variant (the
//    JIT at the first draw that program binaries alone do not skip).
//    EnableShaderCache() points Mesa there unless the environment already
//    sets MESA_SHADER_CACHE_DIR or MESA_SHADER_CACHE_DISABLE.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "render/gl/handles.h"

namespace render {

// $IBR_CACHE_DIR if set ("off" or empty: no cache; returns empty), else
// $XDG_CACHE_HOME/ibr, else $HOME/.cache/ibr; empty when none is set.
std::filesystem::path DefaultShaderCacheDir();

// Process-wide: ProgramCaches created afterwards keep binaries under
// `dir`/programs; Mesa's cache goes to `dir`/mesa (see above). Call before the
// first GL context is created (Mesa reads its variables then). An empty `dir`
// turns our layer off and leaves Mesa's settings alone.
void EnableShaderCache(const std::filesystem::path& dir);
// The directory EnableShaderCache() was given (empty: off; tests leave it off).
const std::filesystem::path& ShaderCacheDir();

// One directory of program binaries. Needs the context current for Load and
// Store (the driver strings and GL_NUM_PROGRAM_BINARY_FORMATS are read on
// first use).
class ProgramBinaryCache {
 public:
  explicit ProgramBinaryCache(std::filesystem::path dir) : dir_(std::move(dir)) {}

  // The linked program for `key_text` (every source byte and the program's
  // key; the driver strings are appended here), or nullopt on a miss of any
  // kind (no file, other key, corrupt file, refused by the driver).
  std::optional<Program> Load(const std::string& key_text);
  // Saves `program` (linked, ideally with GL_PROGRAM_BINARY_RETRIEVABLE_HINT)
  // for `key_text`; a failure to write is logged and otherwise ignored (the
  // cache is an optimisation, never a reason to stop).
  void Store(const std::string& key_text, const Program& program);

  // False when the driver offers no binary format (nothing is read or written).
  bool available();
  // The file a key is kept in (hash of key + driver).
  std::filesystem::path PathFor(const std::string& key_text);
  const std::filesystem::path& dir() const { return dir_; }
  // The driver identity appended to every key (for tests: another driver string).
  void set_driver_for_testing(std::string driver) { driver_ = std::move(driver); }

  struct Stats {
    int hits = 0;      // programs loaded from a binary
    int misses = 0;    // no file for the key
    int rejected = 0;  // a file that did not match, was corrupt or was refused
    int stored = 0;    // binaries written
  };
  const Stats& stats() const { return stats_; }

 private:
  void Init();
  std::string FullKey(const std::string& key_text);

  std::filesystem::path dir_;
  std::optional<std::string> driver_;
  std::optional<bool> available_;
  Stats stats_;
};

}  // namespace render
