#include "render/gl/shader_program.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstring>
#include <optional>
#include <regex>
#include <set>
#include <sstream>

#include "core/error.h"
#include "render/gl/program_binary_cache.h"
#include "shaders/embedded.h"

namespace render {

const ShaderSources& ShaderSources::Embedded() {
  static const ShaderSources embedded = [] {
    std::map<std::string, std::string> files;
    for (const auto& f : shaders::EmbeddedFiles()) files.emplace(f.name, f.source);
    return ShaderSources(std::move(files));
  }();
  return embedded;
}

const std::string* ShaderSources::Find(const std::string& name) const {
  auto it = files_.find(name);
  return it == files_.end() ? nullptr : &it->second;
}

std::vector<std::string> ShaderSources::Names() const {
  std::vector<std::string> names;
  for (const auto& [name, _] : files_) names.push_back(name);
  return names;
}

std::string ProgramDesc::Key() const {
  std::vector<std::string> sorted = defines;
  std::sort(sorted.begin(), sorted.end());
  std::string key = fmt::format("v={}|g={}|f={}|c={}", vertex, geometry, fragment, compute);
  for (const auto& d : sorted) key += "|" + d;
  return key;
}

namespace {

bool IsIdentifier(const std::string& s) {
  static const std::regex re("[A-Za-z_][A-Za-z0-9_]*");
  return std::regex_match(s, re);
}

std::vector<std::string> SplitLines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.push_back(line);
  }
  return lines;
}

struct Preprocessor {
  const ShaderSources& sources;
  PreprocessedSource out;
  std::set<std::string> included;
  std::vector<std::string> stack;

  void Emit(const std::string& file, bool is_root, const std::vector<std::string>& defines) {
    const std::string* text = sources.Find(file);
    if (!text) core::ThrowFileError("PreprocessShader", file, "no such shader file");
    if (std::find(stack.begin(), stack.end(), file) != stack.end()) {
      core::ThrowFileError("PreprocessShader", file, "include cycle");
    }
    stack.push_back(file);
    const int id = static_cast<int>(out.files.size());
    out.files.push_back(file);
    static const std::regex include_re(R"re(^\s*#\s*include\s+"([^"]+)"\s*(//.*)?$)re");
    static const std::regex version_re(R"(^\s*#\s*version\b.*$)");
    const std::vector<std::string> lines = SplitLines(*text);
    size_t first = 0;
    if (is_root) {
      if (lines.empty() || !std::regex_match(lines[0], version_re)) {
        core::ThrowFileError("PreprocessShader", file, "the first line must be #version");
      }
      out.text += lines[0] + "\n";
      for (const auto& d : defines) out.text += "#define " + d + "\n";
      first = 1;
    }
    // GLSL >= 3.30: after "#line L S" the next line is line L of string S.
    out.text += fmt::format("#line {} {}\n", first + 1, id);
    for (size_t i = first; i < lines.size(); ++i) {
      std::smatch m;
      if (std::regex_match(lines[i], m, include_re)) {
        const std::string child = m[1].str();
        if (!included.contains(child)) {
          included.insert(child);
          Emit(child, false, {});
        }
        out.text += fmt::format("#line {} {}\n", i + 2, id);
      } else if (lines[i].find("#include") != std::string::npos &&
                 lines[i].find_first_not_of(" \t") == lines[i].find('#')) {
        core::ThrowFileError("PreprocessShader", file,
                             "line {}: malformed #include (use #include \"name.glsl\")", i + 1);
      } else if (!is_root && std::regex_match(lines[i], version_re)) {
        core::ThrowFileError("PreprocessShader", file,
                             "line {}: an included chunk must not have #version", i + 1);
      } else {
        out.text += lines[i] + "\n";
      }
    }
    stack.pop_back();
  }
};

}  // namespace

void ProgramDesc::Check() const {
  const bool graphics = !vertex.empty() && !fragment.empty();
  const bool compute_only =
      !compute.empty() && vertex.empty() && fragment.empty() && geometry.empty();
  if (!graphics && !compute_only) {
    core::ThrowInputError(
        "ProgramDesc", "need vertex+fragment (optionally geometry) or compute alone ({})", Key());
  }
  for (const auto& d : defines) {
    const std::string name = d.substr(0, d.find(' '));
    if (!IsIdentifier(name)) core::ThrowInputError("ProgramDesc", "bad define '{}'", d);
  }
}

PreprocessedSource PreprocessShader(const ShaderSources& sources, const std::string& file,
                                    const std::vector<std::string>& defines) {
  for (const auto& d : defines) {
    if (!IsIdentifier(d.substr(0, d.find(' ')))) {
      core::ThrowFileError("PreprocessShader", file, "bad define '{}'", d);
    }
  }
  Preprocessor pp{sources, {}, {}, {}};
  pp.Emit(file, true, defines);
  return std::move(pp.out);
}

std::string TranslateShaderLog(const std::string& log, const std::vector<std::string>& files) {
  // Mesa: "0:12(3): error: ..."; NVIDIA: "0(12) : error C1008: ...".
  static const std::regex mesa_re(R"((^|\n)(\d+):(\d+)\((\d+)\))");
  static const std::regex nvidia_re(R"((^|\n)(\d+)\((\d+)\))");
  auto name_of = [&](const std::string& id) {
    const size_t i = std::stoul(id);
    return i < files.size() ? files[i] : fmt::format("string{}", id);
  };
  std::string result;
  auto rewrite = [&](const std::string& text, const std::regex& re, bool mesa) {
    std::string out;
    auto begin = std::sregex_iterator(text.begin(), text.end(), re);
    size_t last = 0;
    for (auto it = begin; it != std::sregex_iterator(); ++it) {
      const std::smatch& m = *it;
      out += text.substr(last, m.position(0) - last);
      out += fmt::format("{}{}:{}", m[1].str(), name_of(m[2].str()), m[3].str());
      if (mesa) out += fmt::format("({})", m[4].str());
      last = m.position(0) + m.length(0);
    }
    return out + text.substr(last);
  };
  result = rewrite(log, mesa_re, true);
  return rewrite(result, nvidia_re, false);
}

namespace {

// The info log of a shader or program (glGetShaderiv + glGetShaderInfoLog,
// or the program pair), without its terminating NUL.
template <typename GetIv, typename GetLog>
std::string InfoLog(GLuint id, GetIv get_iv, GetLog get_log) {
  GLint length = 0;
  get_iv(id, GL_INFO_LOG_LENGTH, &length);
  std::string log(static_cast<size_t>(std::max(length, 1)), '\0');
  get_log(id, length, nullptr, log.data());
  log.resize(std::strlen(log.c_str()));
  return log;
}

Shader CompileStage(GLenum stage, const std::string& file, const PreprocessedSource& pre,
                    const std::vector<std::string>& defines) {
  Shader shader(glCreateShader(stage));
  const char* text = pre.text.c_str();
  glShaderSource(shader.id(), 1, &text, nullptr);
  glCompileShader(shader.id());
  GLint ok = GL_FALSE;
  glGetShaderiv(shader.id(), GL_COMPILE_STATUS, &ok);
  if (!ok) {
    const std::string log = InfoLog(shader.id(), glGetShaderiv, glGetShaderInfoLog);
    std::string translated = TranslateShaderLog(log, pre.files);
    while (!translated.empty() && (translated.back() == '\n' || translated.back() == ' '))
      translated.pop_back();
    // One line for the CLI: the first error first, the rest after " | ".
    std::string one_line;
    for (const auto& line : SplitLines(translated)) {
      if (line.empty()) continue;
      one_line += (one_line.empty() ? "" : " | ") + line;
    }
    std::string defs;
    for (const auto& d : defines) defs += (defs.empty() ? "" : ",") + d;
    core::ThrowInputError("BuildProgram", "compile error in {}{}: {}", file,
                          defs.empty() ? "" : " [" + defs + "]", one_line);
  }
  return shader;
}

}  // namespace

ProgramSources PreprocessProgram(const ShaderSources& sources, const ProgramDesc& desc) {
  desc.Check();
  ProgramSources out;
  auto add = [&](GLenum type, const std::string& file) {
    if (!file.empty())
      out.stages.push_back({type, file, PreprocessShader(sources, file, desc.defines)});
  };
  if (!desc.compute.empty()) {
    add(GL_COMPUTE_SHADER, desc.compute);
  } else {
    add(GL_VERTEX_SHADER, desc.vertex);
    add(GL_GEOMETRY_SHADER, desc.geometry);
    add(GL_FRAGMENT_SHADER, desc.fragment);
  }
  return out;
}

std::string ProgramSources::CacheKey(const ProgramDesc& desc) const {
  std::string key = desc.Key() + "\n";
  for (const Stage& s : stages) {
    key += fmt::format("stage {:#x} {} {} bytes\n", s.type, s.file, s.source.text.size());
    key += s.source.text;
  }
  return key;
}

Program BuildProgram(const ProgramSources& sources, const ProgramDesc& desc, bool retrievable) {
  std::vector<Shader> stages;
  for (const ProgramSources::Stage& s : sources.stages)
    stages.push_back(CompileStage(s.type, s.file, s.source, desc.defines));
  Program program(glCreateProgram());
  if (retrievable) glProgramParameteri(program.id(), GL_PROGRAM_BINARY_RETRIEVABLE_HINT, GL_TRUE);
  for (const auto& s : stages) glAttachShader(program.id(), s.id());
  glLinkProgram(program.id());
  for (const auto& s : stages) glDetachShader(program.id(), s.id());
  GLint ok = GL_FALSE;
  glGetProgramiv(program.id(), GL_LINK_STATUS, &ok);
  if (!ok) {
    std::string log = InfoLog(program.id(), glGetProgramiv, glGetProgramInfoLog);
    std::replace(log.begin(), log.end(), '\n', ' ');
    core::ThrowInputError("BuildProgram", "link error in {}: {}", desc.Key(), log);
  }
  program.CacheUniforms();
  return program;
}

Program BuildProgram(const ShaderSources& sources, const ProgramDesc& desc) {
  return BuildProgram(PreprocessProgram(sources, desc), desc);
}

ProgramCache::ProgramCache(const ShaderSources& sources)
    : ProgramCache(sources, ShaderCacheDir().empty() ? std::filesystem::path()
                                                     : ShaderCacheDir() / "programs") {}

ProgramCache::ProgramCache(const ShaderSources& sources, const std::filesystem::path& disk_dir)
    : sources_(&sources) {
  if (!disk_dir.empty()) disk_ = std::make_unique<ProgramBinaryCache>(disk_dir);
}

ProgramCache::~ProgramCache() = default;

const Program& ProgramCache::Get(const ProgramDesc& desc) {
  const std::string key = desc.Key();
  auto it = programs_.find(key);
  if (it != programs_.end()) return *it->second;
  const ProgramSources sources = PreprocessProgram(*sources_, desc);
  for (const std::string* file : {&desc.vertex, &desc.geometry, &desc.fragment, &desc.compute}) {
    if (!file->empty()) ++compiled_by_file_[*file];
  }
  std::unique_ptr<Program> program;
  std::string disk_key;
  if (disk_) {
    disk_key = sources.CacheKey(desc);
    if (std::optional<Program> loaded = disk_->Load(disk_key)) {
      loaded->CacheUniforms();
      return *programs_.emplace(key, std::make_unique<Program>(std::move(*loaded))).first->second;
    }
  }
  spdlog::debug("compiling program {}", key);
  program = std::make_unique<Program>(BuildProgram(sources, desc, disk_ != nullptr));
  if (disk_) disk_->Store(disk_key, *program);
  return *programs_.emplace(key, std::move(program)).first->second;
}

}  // namespace render
