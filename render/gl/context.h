// OpenGL contexts. The headless context is EGL with no display: the Mesa
// surfaceless platform first, then the EGL device platform (what NVIDIA's
// driver offers), then the default display. It asks for desktop GL 4.5 core and
// falls back to 4.3 and 3.3. Rendering goes into framebuffer objects.
#pragma once

#include <memory>
#include <string>

namespace render {

struct GlInfo {
  std::string platform;  // "surfaceless", "device", "default" or "window"
  std::string vendor;
  std::string renderer;
  std::string version;
  std::string glsl_version;
  int major = 0;
  int minor = 0;
  bool debug = false;  // a KHR_debug callback is installed
};

struct HeadlessContextOptions {
  // Ask for a debug context and route KHR_debug messages to the logger.
  // Default: on in debug builds, or when the environment sets IBR_GL_DEBUG=1.
  bool debug = DefaultDebug();

  static bool DefaultDebug();
};

// Owns an EGL display + context and keeps it current on the creating thread.
class HeadlessContext {
 public:
  // Throws core::InputError with one line naming every platform tried and why
  // it failed when no context can be made.
  static std::unique_ptr<HeadlessContext> Create(const HeadlessContextOptions& options = {});
  ~HeadlessContext();
  HeadlessContext(const HeadlessContext&) = delete;
  HeadlessContext& operator=(const HeadlessContext&) = delete;

  const GlInfo& info() const { return info_; }
  void MakeCurrent();

 private:
  HeadlessContext() = default;
  struct Egl;
  std::unique_ptr<Egl> egl_;
  GlInfo info_;
};

// Called once a context (headless or window) is current: reads the GL info,
// checks the version is at least 3.3 core, installs the debug callback if
// requested. The viewer's GLFW window context goes through this too.
GlInfo InitializeCurrentContext(const std::string& platform, bool debug);

}  // namespace render
