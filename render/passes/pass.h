// The one contract every pass implements (mesh, slice displacement,
// relief/NCS/POM, depth objects and visual hulls, volumes, cuts and
// deformations), and the one frame they all draw into.
//
// A pass is built from plain CPU data (meshes, images, volumes) and an options
// struct; the constructor calls `options.Check()` (bad values throw
// core::InputError) and uploads what it needs. The options struct alone decides
// the shader variant: each pass has one function that turns options into
// `#define`s (`Defines()`), so the program cache compiles only the variants a
// scene uses. `Draw` draws the pass's object into a frame target that
// BeginFrame started, depth-tested (LESS) against what earlier passes left
// there, so several passes drawn into one target composite by depth.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <string_view>

#include "core/image.h"
#include "render/gl/handles.h"
#include "render/gl/render_target.h"

namespace render {

// Where the camera is and how it projects (see core/projection.h).
struct ViewSetup {
  glm::mat4 cam_from_world{1.0f};
  glm::mat4 clip_from_cam{1.0f};
  bool orthographic = false;
};

// Attachment indices of a frame target (FrameTargetOptions). Every pass
// writes the first three at these fragment-output locations (a pass without
// normals writes 0). The outcome attachment is NOT a draw target: BeginFrame
// masks it, and a pass that reports outcomes ORs bits into it as an image
// (BindOutcomeImage + imageAtomicOr in the shader), for every ray it casts,
// kept or discarded, visible or hidden; so the composite's bits are the OR of
// every pass's in any draw order. Bits are pass-defined (ray passes use
// 1u << RayOutcome).
enum FrameAttachment : int {
  kFrameColor = 0,    // RGBA8: shaded colour, alpha 255 where covered
  kFrameCameraZ = 1,  // R32F: camera z in scene units, 0 where empty
  kFrameNormal = 2,   // RGBA16F: world-space unit normal (xyz), 0 where empty or unknown
  kFrameOutcome = 3,  // R32UI image: OR of outcome bits, 0 = none
};

// Binds the frame's outcome attachment to image unit `unit` (r32ui,
// read-write) for imageAtomicOr.
void BindOutcomeImage(const RenderTarget& target, GLuint unit = 0);

// The frame target every pass draws into: the four attachments above plus a
// D24S8 depth/stencil buffer holding window depth (the compositing test).
RenderTargetOptions FrameTargetOptions(int width, int height);

// Bytes per pixel of a FrameTargetOptions target (colour 4 + camera z 4 +
// normal 8 + outcome 4 + depth/stencil 4 = 24).
int64_t FrameBytesPerPixel();

// The one check of every frame size a user asks for (`--size` of every
// command), before anything of that size is allocated: both sides in
// 1..`limits` (GL_MAX_RENDERBUFFER_SIZE, GL_MAX_TEXTURE_SIZE,
// GL_MAX_VIEWPORT_DIMS) and the frame's estimate, 2 x FrameBytesPerPixel() x
// pixels (the target and its readback), within the memory budget
// (core::CheckMemory, --memory-budget).
// Throws core::InputError("where: flag: ...") naming the requested size and
// the limit it breaks. The second form queries the current context's limits.
// `min_side`: the command's smallest useful side (below it: "below the minimum").
void CheckFrameSize(std::string_view where, std::string_view flag, int width, int height,
                    const GlSizeLimits& limits, int min_side = 1);
void CheckFrameSize(std::string_view where, std::string_view flag, int width, int height,
                    int min_side = 1);

// Binds `target` and clears it for a new frame: colour, camera z, normal and
// outcome to 0, depth to 1, stencil to 0; depth test LESS on, no stencil,
// blending or face culling, the outcome draw buffer masked (the state every
// pass may assume on entry and must leave).
void BeginFrame(const RenderTarget& target);

// The start of a pass's draw: binds `target`, makes `program` current and sets
// its view uniforms u_cam_from_world and u_clip_from_cam (either may be
// absent from the program).
void UseProgram(const RenderTarget& target, const Program& program, const ViewSetup& view);

// A frame read back to the CPU (rows top first, like core::Image): the one
// readback type of every pass, scene and depth object. Empty pixels are 0 in
// every attachment (BeginFrame's clear; no pass writes a background).
struct Frame {
  core::Image8 color;             // RGBA8, alpha 255 where covered
  core::ImageF depth;             // 1 channel camera z (scene units), 0 where empty
  core::ImageF normal;            // 3 channels, world space, 0 where empty or unknown
  core::Image<uint32_t> outcome;  // 1 channel of outcome bits
  // Coverage = colour alpha 255 (every pass writes alpha 255 where it drew).
  bool Covered(int x, int y) const { return color.at(x, y, 3) == 255; }
  // Pixels Covered.
  int64_t CoveredPixels() const;
  // Pixels whose outcome has any of `bits` set.
  int64_t CountOutcome(uint32_t bits) const;
};

// The frame's coverage as a 1-channel mask: 255 where Covered, else 0 (a
// dataset's mask image).
core::Image8 CoverageMask(const Frame& frame);

// Reads back every attachment of a target made with FrameTargetOptions.
Frame ReadFrame(const RenderTarget& target);

// Every pass. Draw() requires the state BeginFrame leaves (depth test LESS,
// target bound) and leaves it so; it never clears the target.
class Pass {
 public:
  virtual ~Pass() = default;
  // A short stable name ("mesh", "displacement", "relief", "depth-object", ...).
  virtual std::string_view name() const = 0;
  virtual void Draw(const RenderTarget& target, const ViewSetup& view) = 0;
  // True for a pass that blends over what is already in the frame (volume
  // DVR) instead of writing depth: a scene draws these after every opaque
  // pass, so they blend over what the depth test lets through.
  virtual bool translucent() const { return false; }
};

// BeginFrame + pass.Draw: one whole frame of one pass into `target` (what a
// benchmark times).
void DrawFrame(const RenderTarget& target, Pass& pass, const ViewSetup& view);

// BeginFrame on a fresh FrameTargetOptions target, pass.Draw, ReadFrame.
Frame RenderFrame(Pass& pass, const ViewSetup& view, int width, int height);

}  // namespace render
