#include "render/gl/context.h"

#include <epoxy/egl.h>
#include <spdlog/spdlog.h>

#include <cstdlib>
#include <vector>

#include "core/error.h"
#include "render/gl/gl.h"
#include "render/gl/gl_debug.h"

namespace render {

bool HeadlessContextOptions::DefaultDebug() {
  if (const char* env = std::getenv("IBR_GL_DEBUG")) return std::string(env) == "1";
#ifdef NDEBUG
  return false;
#else
  return true;
#endif
}

struct HeadlessContext::Egl {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
};

namespace {

std::string EglErrorName(EGLint error) {
  switch (error) {
    case EGL_SUCCESS:
      return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS:
      return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER:
      return "EGL_BAD_PARAMETER";
    default:
      return fmt::format("EGL error 0x{:x}", error);
  }
}

bool HasClientExtension(const char* name) {
  const char* extensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!extensions) return false;
  const std::string list = std::string(" ") + extensions + " ";
  return list.find(std::string(" ") + name + " ") != std::string::npos;
}

struct DisplayCandidate {
  std::string platform;
  EGLDisplay display;
};

// In order of preference; a platform that is not offered is reported as such.
std::vector<DisplayCandidate> CandidateDisplays(std::vector<std::string>& failures) {
  std::vector<DisplayCandidate> candidates;
  const bool has_platform_base = HasClientExtension("EGL_EXT_platform_base");
  if (has_platform_base && HasClientExtension("EGL_MESA_platform_surfaceless")) {
    EGLDisplay d =
        eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (d != EGL_NO_DISPLAY)
      candidates.push_back({"surfaceless", d});
    else
      failures.push_back("surfaceless: " + EglErrorName(eglGetError()));
  } else {
    failures.push_back("surfaceless: not offered");
  }
  if (has_platform_base && HasClientExtension("EGL_EXT_platform_device") &&
      HasClientExtension("EGL_EXT_device_enumeration")) {
    EGLDeviceEXT devices[8];
    EGLint count = 0;
    if (eglQueryDevicesEXT(8, devices, &count) && count > 0) {
      for (EGLint i = 0; i < count; ++i) {
        EGLDisplay d = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
        if (d != EGL_NO_DISPLAY) candidates.push_back({fmt::format("device{}", i), d});
      }
    } else {
      failures.push_back("device: no EGL device");
    }
  } else {
    failures.push_back("device: not offered");
  }
  EGLDisplay d = eglGetDisplay(EGL_DEFAULT_DISPLAY);
  if (d != EGL_NO_DISPLAY)
    candidates.push_back({"default", d});
  else
    failures.push_back("default: " + EglErrorName(eglGetError()));
  return candidates;
}

// Tries to make a desktop GL core context on `display`; returns EGL_NO_CONTEXT
// and appends the reason on failure.
EGLContext TryCreateContext(EGLDisplay display, bool debug, std::string& failure) {
  EGLint major = 0, minor = 0;
  if (!eglInitialize(display, &major, &minor)) {
    failure = "eglInitialize: " + EglErrorName(eglGetError());
    return EGL_NO_CONTEXT;
  }
  if (!eglBindAPI(EGL_OPENGL_API)) {
    failure = "eglBindAPI(OpenGL): " + EglErrorName(eglGetError());
    return EGL_NO_CONTEXT;
  }
  // EGL_SURFACE_TYPE 0: any config; we never make an EGL surface.
  const EGLint config_attribs[] = {EGL_SURFACE_TYPE, 0,  EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                   EGL_RED_SIZE,     8,  EGL_GREEN_SIZE,      8,
                                   EGL_BLUE_SIZE,    8,  EGL_ALPHA_SIZE,      8,
                                   EGL_DEPTH_SIZE,   24, EGL_STENCIL_SIZE,    8,
                                   EGL_NONE};
  EGLConfig config = nullptr;
  EGLint num_configs = 0;
  if (!eglChooseConfig(display, config_attribs, &config, 1, &num_configs) || num_configs < 1) {
    failure = "no RGBA8/D24S8 OpenGL config";
    return EGL_NO_CONTEXT;
  }
  // GL 4.6 gives EGL_BAD_MATCH on Mesa 22 (HEADLESS-GL.md): ask 4.5 first.
  const int versions[][2] = {{4, 5}, {4, 3}, {3, 3}};
  for (const auto& v : versions) {
    std::vector<EGLint> attribs = {
        EGL_CONTEXT_MAJOR_VERSION,       v[0],
        EGL_CONTEXT_MINOR_VERSION,       v[1],
        EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT};
    if (debug) attribs.insert(attribs.end(), {EGL_CONTEXT_OPENGL_DEBUG, EGL_TRUE});
    attribs.push_back(EGL_NONE);
    EGLContext ctx = eglCreateContext(display, config, EGL_NO_CONTEXT, attribs.data());
    if (ctx != EGL_NO_CONTEXT) return ctx;
    failure = fmt::format("GL {}.{} core: {}", v[0], v[1], EglErrorName(eglGetError()));
  }
  return EGL_NO_CONTEXT;
}

}  // namespace

std::unique_ptr<HeadlessContext> HeadlessContext::Create(const HeadlessContextOptions& options) {
  std::vector<std::string> failures;
  for (const DisplayCandidate& candidate : CandidateDisplays(failures)) {
    std::string failure;
    EGLContext ctx = TryCreateContext(candidate.display, options.debug, failure);
    if (ctx == EGL_NO_CONTEXT) {
      failures.push_back(candidate.platform + ": " + failure);
      eglTerminate(candidate.display);
      continue;
    }
    if (!eglMakeCurrent(candidate.display, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
      failures.push_back(candidate.platform +
                         ": eglMakeCurrent (surfaceless): " + EglErrorName(eglGetError()));
      eglDestroyContext(candidate.display, ctx);
      eglTerminate(candidate.display);
      continue;
    }
    std::unique_ptr<HeadlessContext> context(new HeadlessContext());
    context->egl_ = std::make_unique<Egl>();
    context->egl_->display = candidate.display;
    context->egl_->context = ctx;
    const std::string platform =
        candidate.platform.starts_with("device") ? std::string("device") : candidate.platform;
    context->info_ = InitializeCurrentContext(platform, options.debug);
    return context;
  }
  std::string all;
  for (const auto& f : failures) all += (all.empty() ? "" : "; ") + f;
  core::ThrowInputError("HeadlessContext::Create", "no OpenGL 3.3+ core context could be made ({})",
                        all);
}

HeadlessContext::~HeadlessContext() {
  if (egl_) {
    eglMakeCurrent(egl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(egl_->display, egl_->context);
    eglTerminate(egl_->display);
  }
}

void HeadlessContext::MakeCurrent() {
  eglMakeCurrent(egl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, egl_->context);
}

GlInfo InitializeCurrentContext(const std::string& platform, bool debug) {
  GlInfo info;
  info.platform = platform;
  auto str = [](GLenum name) {
    const auto* s = reinterpret_cast<const char*>(glGetString(name));
    return s ? std::string(s) : std::string();
  };
  info.vendor = str(GL_VENDOR);
  info.renderer = str(GL_RENDERER);
  info.version = str(GL_VERSION);
  info.glsl_version = str(GL_SHADING_LANGUAGE_VERSION);
  glGetIntegerv(GL_MAJOR_VERSION, &info.major);
  glGetIntegerv(GL_MINOR_VERSION, &info.minor);
  if (info.major * 10 + info.minor < 33) {
    core::ThrowInputError("InitializeCurrentContext", "OpenGL {}.{} is too old (need 3.3 core)",
                          info.major, info.minor);
  }
  if (debug) info.debug = InstallDebugCallback();
  spdlog::debug("GL context ({}): {} | {} | {}", info.platform, info.version, info.renderer,
                info.vendor);
  return info;
}

}  // namespace render
