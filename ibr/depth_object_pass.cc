#include "ibr/depth_object_pass.h"

namespace ibr {

ViewCamera ViewCameraFromSetup(const render::ViewSetup& view, int width, int height) {
  const glm::dmat4 m(view.clip_from_cam);  // column-major: m[col][row]
  ViewCamera v;
  const double fx = m[0][0] * width / 2, fy = -m[1][1] * height / 2;
  if (view.orthographic) {
    v.camera = MapCamera::Orthographic(width, height, fx, fy, (m[3][0] + 1) * width / 2,
                                       (1 - m[3][1]) * height / 2);
  } else {
    v.camera = MapCamera::Pinhole(width, height, fx, fy, (m[2][0] + 1) * width / 2,
                                  (1 - m[2][1]) * height / 2);
  }
  v.cam_from_world = glm::dmat4(view.cam_from_world);
  return v;
}

DepthObjectPass::DepthObjectPass(render::ProgramCache& programs, MapSet maps,
                                 const DepthObjectOptions& options)
    : renderer_(programs, std::move(maps)), options_(options) {
  options_.Check();
}

std::string_view DepthObjectPass::name() const {
  return options_.method == Method::kDepthObject ? "depth-object" : "visual-hull";
}

void DepthObjectPass::set_options(const DepthObjectOptions& options) {
  options.Check();
  options_ = options;
}

void DepthObjectPass::Draw(const render::RenderTarget& target, const render::ViewSetup& view) {
  renderer_.DrawToFrame(ViewCameraFromSetup(view, target.width(), target.height()), options_,
                        view.clip_from_cam, target);
}

}  // namespace ibr
