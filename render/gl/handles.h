// Move-only owners of GL object names (Magnum's GL::Buffer model): copy is
// deleted, move is noexcept and zeroes the source, the destructor skips name 0.
// One template over a deleter; thin typed classes on top. Objects are created
// with DSA (glCreate*), so a name is a complete object as soon as it exists.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <typeindex>
#include <typeinfo>
#include <unordered_map>
#include <utility>

#include "render/gl/gl.h"

namespace render {

template <typename Deleter>
class GlHandle {
 public:
  GlHandle() noexcept = default;
  explicit GlHandle(GLuint id) noexcept : id_(id) {}
  ~GlHandle() { Reset(); }
  GlHandle(const GlHandle&) = delete;
  GlHandle& operator=(const GlHandle&) = delete;
  GlHandle(GlHandle&& other) noexcept : id_(std::exchange(other.id_, 0)) {}
  GlHandle& operator=(GlHandle&& other) noexcept {
    if (this != &other) {
      Reset();
      id_ = std::exchange(other.id_, 0);
    }
    return *this;
  }

  GLuint id() const noexcept { return id_; }
  explicit operator bool() const noexcept { return id_ != 0; }
  // Gives up ownership without deleting.
  GLuint Release() noexcept { return std::exchange(id_, 0); }
  void Reset() noexcept {
    if (id_ != 0) Deleter::Delete(id_);
    id_ = 0;
  }

 private:
  GLuint id_ = 0;
};

namespace deleters {
struct Buffer {
  static void Delete(GLuint id) { glDeleteBuffers(1, &id); }
};
struct Texture {
  static void Delete(GLuint id) { glDeleteTextures(1, &id); }
};
struct Renderbuffer {
  static void Delete(GLuint id) { glDeleteRenderbuffers(1, &id); }
};
struct Framebuffer {
  static void Delete(GLuint id) { glDeleteFramebuffers(1, &id); }
};
struct VertexArray {
  static void Delete(GLuint id) { glDeleteVertexArrays(1, &id); }
};
struct Query {
  static void Delete(GLuint id) { glDeleteQueries(1, &id); }
};
struct Shader {
  static void Delete(GLuint id) { glDeleteShader(id); }
};
struct Program {
  static void Delete(GLuint id) { glDeleteProgram(id); }
};
}  // namespace deleters

class Buffer : public GlHandle<deleters::Buffer> {
 public:
  using GlHandle::GlHandle;
  static Buffer Create();
  // Immutable storage (glNamedBufferStorage) of `bytes` bytes from `data`.
  static Buffer CreateWithData(const void* data, GLsizeiptr bytes, GLbitfield flags = 0);
};

class Texture : public GlHandle<deleters::Texture> {
 public:
  Texture() noexcept = default;
  static Texture Create(GLenum target);
  // Textures created so far by this process (every Create* goes through
  // Create): tests count what a scene allocates.
  static int64_t created_count();
  // Immutable 2D/3D storage, one level, with NEAREST filtering and
  // CLAMP_TO_EDGE by default (callers change them as the pass needs).
  static Texture Create2D(GLenum internal_format, int width, int height);
  static Texture Create3D(GLenum internal_format, int width, int height, int depth);
  // Immutable 1D storage, one level, NEAREST and CLAMP_TO_EDGE, filled from
  // `data` (`width` texels in `format` and `type`): lookup tables.
  static Texture Create1DWithData(GLenum internal_format, int width, GLenum format, GLenum type,
                                  const void* data);
  // Create3D plus one upload of the whole level from `data`: tightly packed
  // texels in `format` and `type` (as glTextureSubImage3D takes them; the
  // unpack alignment is 1 for the upload and restored after).
  static Texture Create3DWithData(GLenum internal_format, const glm::ivec3& dims, GLenum format,
                                  GLenum type, const void* data);
  // LINEAR minification and magnification (Create2D/Create3D default to
  // NEAREST); the wrap modes are left as they are.
  Texture& SetLinearFilter();
  GLenum target() const noexcept { return target_; }
  Texture(Texture&& other) noexcept = default;
  Texture& operator=(Texture&& other) noexcept = default;

 private:
  Texture(GLuint id, GLenum target) noexcept : GlHandle(id), target_(target) {}
  GLenum target_ = 0;
};

class Renderbuffer : public GlHandle<deleters::Renderbuffer> {
 public:
  using GlHandle::GlHandle;
  static Renderbuffer Create(GLenum internal_format, int width, int height);
};

class Framebuffer : public GlHandle<deleters::Framebuffer> {
 public:
  using GlHandle::GlHandle;
  static Framebuffer Create();
};

class VertexArray : public GlHandle<deleters::VertexArray> {
 public:
  using GlHandle::GlHandle;
  static VertexArray Create();
};

class Query : public GlHandle<deleters::Query> {
 public:
  using GlHandle::GlHandle;
  static Query Create(GLenum target);
};

class Shader : public GlHandle<deleters::Shader> {
 public:
  using GlHandle::GlHandle;
};

// A linked program with its uniform locations, looked up once at link
// (CacheUniforms, called by BuildProgram), as Magnum's shaders cache every
// location in their constructor. Code outside render/gl sets uniforms only
// through a typed struct of Uniform<T> handles (render/gl/uniform.h) that
// Typed<T>() builds once per linked program; the by-name setters below are
// render/gl's own plumbing (and what the typed handles are tested against).
class Program : public GlHandle<deleters::Program> {
 public:
  using GlHandle::GlHandle;
  Program() noexcept = default;
  Program(Program&&) noexcept = default;
  Program& operator=(Program&&) noexcept = default;
  // Reads every active uniform's location (array elements beyond [0] are
  // resolved once on first use). Called once after a successful link; drops
  // the typed structs built for an earlier link.
  void CacheUniforms();
  // Uniform location by name, -1 if the linker removed it (not an error: a
  // variant may not use it). No GL call once cached.
  GLint Uniform(std::string_view name) const;
  void Use() const { glUseProgram(id()); }

  // The typed uniform struct T of this program (T has a constructor
  // `explicit T(const Program&)` that looks up its Uniform<> handles), built
  // on the first call and kept with the program: every later call, from any
  // pass, is a hash lookup by type, with no name lookup and no GL call.
  template <typename T>
  const T& Typed() const {
    std::shared_ptr<const void>& slot = typed_[std::type_index(typeid(T))];
    if (!slot) slot = std::make_shared<const T>(*this);
    return *static_cast<const T*>(slot.get());
  }

  // By-name setters (render/gl only); a uniform the variant does not have
  // (-1) is ignored.
  void Set(std::string_view name, int value) const;
  void Set(std::string_view name, unsigned value) const;
  void Set(std::string_view name, float value) const;
  void Set(std::string_view name, const glm::vec2& value) const;
  void Set(std::string_view name, const glm::vec3& value) const;
  void Set(std::string_view name, const glm::vec4& value) const;
  void Set(std::string_view name, const glm::ivec2& value) const;
  void Set(std::string_view name, const glm::ivec3& value) const;
  void Set(std::string_view name, const glm::mat3& value) const;
  void Set(std::string_view name, const glm::mat4& value) const;
  void Set(std::string_view name, std::span<const glm::vec4> values) const;
  void Set(std::string_view name, std::span<const glm::mat4> values) const;

 private:
  // name -> location; mutable because array elements are memoised lazily.
  mutable std::unordered_map<std::string, GLint> locations_;
  // Typed<T>() structs by T; mutable because they are built on first use.
  mutable std::unordered_map<std::type_index, std::shared_ptr<const void>> typed_;
};

}  // namespace render
