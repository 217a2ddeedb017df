// Depth objects and visual hulls on the pass contract (render/passes/pass.h):
// the object of one MapSet drawn into a frame target (FrameTargetOptions)
// begun by render::BeginFrame, composited by depth with whatever else the
// frame holds. The accumulation (slices or ray) runs in the renderer's own
// target; the resolve pass then writes colour, camera z, the outcome flags
// and gl_FragDepth into the frame, depth-tested (LESS).
#pragma once

#include <string_view>

#include "ibr/depth_object.h"
#include "render/passes/pass.h"

namespace ibr {

class DepthObjectPass : public render::Pass {
 public:
  // Uploads the maps (InputError on bad maps or options). Needs a current context.
  DepthObjectPass(render::ProgramCache& programs, MapSet maps, const DepthObjectOptions& options);

  // "depth-object" or "visual-hull".
  std::string_view name() const override;
  // The view's intrinsics are recovered from view.clip_from_cam and the
  // target's size (core/projection.h's matrices); its near/far only place
  // gl_FragDepth, so objects of several passes composite by camera z.
  void Draw(const render::RenderTarget& target, const render::ViewSetup& view) override;

  const DepthObjectOptions& options() const { return options_; }
  void set_options(const DepthObjectOptions& options);
  DepthObjectRenderer& renderer() { return renderer_; }

 private:
  DepthObjectRenderer renderer_;
  DepthObjectOptions options_;
};

// The pinhole / orthographic camera of a frame of width x height whose
// projection is view.clip_from_cam (the inverse of core::ClipFromCam*).
ViewCamera ViewCameraFromSetup(const render::ViewSetup& view, int width, int height);

}  // namespace ibr
