#include "render/gl/program_binary_cache.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <string_view>
#include <system_error>
#include <vector>

#include "core/atomic_file.h"

namespace render {

namespace fs = std::filesystem;

namespace {

fs::path& ProcessCacheDir() {
  static fs::path dir;
  return dir;
}

const char* Env(const char* name) {
  const char* v = std::getenv(name);
  return v && *v ? v : nullptr;
}

// File layout (host byte order: a cache is read by the machine that wrote it):
// magic, u64 key length, key, u32 binary format, u64 binary length, binary,
// u64 checksum of key + binary.
constexpr char kMagic[8] = {'I', 'B', 'R', 'P', 'R', 'O', 'G', '1'};

uint64_t Checksum(const std::string& key, std::string_view binary) {
  const uint64_t a = std::hash<std::string_view>{}(key);
  const uint64_t b = std::hash<std::string_view>{}(binary);
  return a ^ (b + 0x9e3779b97f4a7c15ull + (a << 6) + (a >> 2));
}

// Bounded reader over a file's bytes: every read checks what is left.
struct Reader {
  const std::string& bytes;
  size_t at = 0;
  bool Read(void* out, size_t n) {
    if (n > bytes.size() - at) return false;
    std::memcpy(out, bytes.data() + at, n);
    at += n;
    return true;
  }
  bool View(size_t n, std::string_view& out) {
    if (n > bytes.size() - at) return false;
    out = std::string_view(bytes.data() + at, n);
    at += n;
    return true;
  }
};

std::string GlString(GLenum name) {
  const auto* s = reinterpret_cast<const char*>(glGetString(name));
  return s ? s : "";
}

}  // namespace

fs::path DefaultShaderCacheDir() {
  if (const char* v = std::getenv("IBR_CACHE_DIR")) {
    const std::string s = v;
    if (s.empty() || s == "off") return {};
    return fs::path(s);
  }
  if (const char* xdg = Env("XDG_CACHE_HOME")) return fs::path(xdg) / "ibr";
  if (const char* home = Env("HOME")) return fs::path(home) / ".cache" / "ibr";
  return {};
}

void EnableShaderCache(const fs::path& dir) {
  ProcessCacheDir() = dir;
  if (dir.empty()) return;
  // Mesa's variables win when the environment sets them (the tests disable
  // Mesa's cache to stay hermetic); otherwise its cache lives beside ours, so
  // clearing one folder makes the next run cold for both.
  if (!Env("MESA_SHADER_CACHE_DIR") && !Env("MESA_SHADER_CACHE_DISABLE") &&
      !Env("MESA_GLSL_CACHE_DIR") && !Env("MESA_GLSL_CACHE_DISABLE")) {
    // Mesa creates only the last folder of the path (else it turns its
    // cache off with a message): make the rest here.
    std::error_code ec;
    fs::create_directories(dir / "mesa", ec);
    if (ec) {
      spdlog::warn("shader cache: cannot create {}: {}", (dir / "mesa").string(), ec.message());
      return;
    }
    ::setenv("MESA_SHADER_CACHE_DIR", (dir / "mesa").c_str(), 1);
  }
}

const fs::path& ShaderCacheDir() { return ProcessCacheDir(); }

void ProgramBinaryCache::Init() {
  if (available_) return;
  GLint formats = 0;
  glGetIntegerv(GL_NUM_PROGRAM_BINARY_FORMATS, &formats);
  available_ = formats > 0;
  if (!driver_) {
    driver_ = fmt::format("{}|{}|{}|{}", GlString(GL_VENDOR), GlString(GL_RENDERER),
                          GlString(GL_VERSION), GlString(GL_SHADING_LANGUAGE_VERSION));
  }
  spdlog::debug("program binary cache {}: {} binary formats, driver {}", dir_.string(), formats,
                *driver_);
}

bool ProgramBinaryCache::available() {
  Init();
  return *available_;
}

std::string ProgramBinaryCache::FullKey(const std::string& key_text) {
  Init();
  return "driver=" + *driver_ + "\n" + key_text;
}

fs::path ProgramBinaryCache::PathFor(const std::string& key_text) {
  return dir_ / fmt::format("{:016x}.bin", std::hash<std::string>{}(FullKey(key_text)));
}

std::optional<Program> ProgramBinaryCache::Load(const std::string& key_text) {
  if (!available()) return std::nullopt;
  const std::string key = FullKey(key_text);
  const fs::path path = PathFor(key_text);
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    if (!in) {
      ++stats_.misses;
      return std::nullopt;
    }
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  auto reject = [&](const char* why) -> std::optional<Program> {
    ++stats_.rejected;
    spdlog::debug("program binary {} not used: {}", path.string(), why);
    return std::nullopt;
  };
  Reader r{bytes};
  char magic[sizeof(kMagic)];
  uint64_t key_length = 0, binary_length = 0, checksum = 0;
  uint32_t format = 0;
  std::string_view stored_key, binary;
  if (!r.Read(magic, sizeof(magic)) || std::memcmp(magic, kMagic, sizeof(kMagic)) != 0)
    return reject("not a program binary file");
  if (!r.Read(&key_length, sizeof(key_length)) || !r.View(key_length, stored_key) ||
      !r.Read(&format, sizeof(format)) || !r.Read(&binary_length, sizeof(binary_length)) ||
      !r.View(binary_length, binary) || !r.Read(&checksum, sizeof(checksum)) ||
      r.at != bytes.size())
    return reject("truncated or malformed");
  if (stored_key != key) return reject("written for another source or driver");
  if (binary.empty() || binary.size() > static_cast<size_t>(INT32_MAX))
    return reject("bad binary length");
  if (checksum != Checksum(key, binary)) return reject("checksum mismatch");
  // A format the driver does not list would be GL_INVALID_ENUM: refuse it here.
  GLint n_formats = 0;
  glGetIntegerv(GL_NUM_PROGRAM_BINARY_FORMATS, &n_formats);
  std::vector<GLint> formats(static_cast<size_t>(std::max(n_formats, 0)));
  if (!formats.empty()) glGetIntegerv(GL_PROGRAM_BINARY_FORMATS, formats.data());
  if (std::find(formats.begin(), formats.end(), static_cast<GLint>(format)) == formats.end())
    return reject("binary format not offered by this driver");
  Program program(glCreateProgram());
  glProgramBinary(program.id(), format, binary.data(), static_cast<GLsizei>(binary.size()));
  GLint ok = GL_FALSE;
  glGetProgramiv(program.id(), GL_LINK_STATUS, &ok);
  if (!ok) return reject("the driver refused it");
  ++stats_.hits;
  return program;
}

void ProgramBinaryCache::Store(const std::string& key_text, const Program& program) {
  if (!available()) return;
  GLint length = 0;
  glGetProgramiv(program.id(), GL_PROGRAM_BINARY_LENGTH, &length);
  if (length <= 0) return;
  std::string binary(static_cast<size_t>(length), '\0');
  GLenum format = 0;
  GLsizei written = 0;
  glGetProgramBinary(program.id(), length, &written, &format, binary.data());
  if (written <= 0) return;
  binary.resize(static_cast<size_t>(written));
  const std::string key = FullKey(key_text);
  const fs::path path = PathFor(key_text);
  try {
    fs::create_directories(dir_);
    core::AtomicWriteStream(
        path,
        [&](std::ostream& out) {
          const uint64_t key_length = key.size(), binary_length = binary.size();
          const uint32_t format32 = format;
          const uint64_t checksum = Checksum(key, binary);
          out.write(kMagic, sizeof(kMagic));
          out.write(reinterpret_cast<const char*>(&key_length), sizeof(key_length));
          out.write(key.data(), static_cast<std::streamsize>(key.size()));
          out.write(reinterpret_cast<const char*>(&format32), sizeof(format32));
          out.write(reinterpret_cast<const char*>(&binary_length), sizeof(binary_length));
          out.write(binary.data(), static_cast<std::streamsize>(binary.size()));
          out.write(reinterpret_cast<const char*>(&checksum), sizeof(checksum));
        },
        core::ExistingFile::kReplace);
    ++stats_.stored;
  } catch (const std::exception& e) {
    spdlog::warn("program cache: cannot write {}: {}", path.string(), e.what());
  }
}

}  // namespace render
