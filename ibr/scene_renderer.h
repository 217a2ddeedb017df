// Renders a scene file (scene/scene.h): builds passes only for the objects it
// names and enables (a scene without displacement compiles no displacement
// program and allocates no displacement texture), draws every object of a
// view into ONE frame target (render/passes/pass.h) and so composites them by
// the depth buffer: mesh (render::MeshPass), displaced mesh (the method's pass,
// ibr/displaced_mesh.h), depth object / visual hull (ibr::DepthObjectPass),
// volume (render::VolumePass; DVR volumes after the opaque objects, their
// slices depth-tested against them), deform (render::DeformPass, built by
// ibr/deform_object.h as `ibr deform` builds it).
//
// Stages: LoadScene (files -> plain CPU data: meshes, height maps, map sets;
// synthetic captures need a context) -> SceneRenderer (GPU upload, passes) ->
// Render per view. Both go through each object's kind (ibr/object_kind.h),
// never a switch over the kinds.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "capture/dataset.h"
#include "capture/synthetic.h"
#include "ibr/deform_object.h"
#include "ibr/depth_object.h"
#include "ibr/displaced_mesh.h"
#include "ibr/image_maps.h"
#include "ibr/kinds/deform_kind.h"
#include "ibr/kinds/volume_kind.h"
#include "ibr/object_kind.h"
#include "ibr/views.h"
#include "ibr/volume_object.h"
#include "render/gl/render_target.h"
#include "render/gl/shader_program.h"
#include "render/passes/pass.h"
#include "scene/scene.h"

namespace ibr {

struct LoadedScene {
  std::string name;
  std::vector<LoadedObject> objects;  // enabled objects only, in scene order
  std::vector<std::string> disabled;  // names of the objects named but disabled
  capture::Bounds bounds;             // world bounds of the enabled objects
  std::vector<NamedView> views;       // the scene's cameras
};

// The scene of one object made in code (the one-object scenes of `ibr
// render DATASET`, `ibr deform`, `ibr volume`, `ibr displace` and `ibr
// demo`): named like the object, its bounds the object's, `views` its cameras.
LoadedScene OneObjectScene(LoadedObject object, std::vector<NamedView> views = {});

// Converts every object's settings by its kind (errors name the file and
// JSON pointer), loads its files and, for captured image sources, renders the capture
// (needs a current context and `programs`). Disabled objects are only checked.
LoadedScene LoadScene(render::ProgramCache& programs, const scene::Scene& scene);

// The maps of a synthetic RGB-D capture of `mesh` (capture::MakeRig's `rig`,
// `size` px, rendered by capture::RenderView) in memory, with the box of the
// mesh's bounds padded by 2 % of their largest extent. Needs a context.
MapSet CaptureMaps(render::ProgramCache& programs, const capture::SceneMesh& mesh,
                   const std::string& rig, int size);

class SceneRenderer {
 public:
  // Uploads and builds one pass per enabled object (ObjectKind::MakePass).
  SceneRenderer(render::ProgramCache& programs, const LoadedScene& scene);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  // BeginFrame once, every pass's Draw into the one frame target (depth
  // test), one readback (render::Frame: alpha 255 and camera z where
  // covered, 0 elsewhere).
  render::Frame Render(const ViewCamera& view);
  // The same frame without the readback: the frame target (render/passes/
  // pass.h: colour attachment 0 RGBA8), valid until the next Draw or Render
  // (the interactive viewer shows it).
  const render::RenderTarget& Draw(const ViewCamera& view);
  // The last Draw's frame read back (what Render would return for its view,
  // without drawing it again: a timed frame's result).
  render::Frame ReadLast() const;
  // The passes built, one per enabled object: "depth-object", "visual-hull",
  // "displacement:METHOD", "mesh", "volume:dvr", "volume:iso", "deform".
  std::vector<std::string> PassNames() const;

  // Changes the options of enabled object `index` of `scene` (the scene this
  // renderer was built from; a deform object) to `options`, rebuilding only
  // what the change invalidates (ibr::UpdateDeformObject: the deformation
  // texture for amounts and widths, the distance field only when the
  // placement, implicit or reach asks for it), then the object's pass, whose
  // textures are uploaded anew (render::DeformPass takes its options at
  // construction), and the object's and the scene's bounds. The next Draw
  // matches a scene loaded with the options the object ends with
  // (DeformOf(scene.objects[index]).options; their sdf_reach says how far the
  // field kept reaches). InputError (nothing changed) on invalid options.
  // `defer_reach` (the viewer while a parameter moves): a field the new
  // displacement outgrows is kept (ibr::UpdateDeformObject), the match above
  // then holds only after an update without it. `prebuilt`: a field built in
  // the background, installed where it serves (ibr::UpdateDeformObject).
  DeformObjectChange UpdateDeform(LoadedScene& scene, size_t index, DeformObjectOptions options,
                                  bool defer_reach = false, DeformFieldBuild* prebuilt = nullptr);
  // The same for a volume object (ibr::UpdateVolumeObject): pass options go
  // to render::VolumePass::SetOptions (no volume upload); effect or map-size
  // changes resample the map and hand it to render::VolumePass::SetMaps (the
  // volume's texture is kept).
  // A new options.transfer goes to render::VolumePass::SetTransferFunction
  // (the table alone is rewritten).
  // `preview`: ibr::UpdateVolumeObject's (a rougher peel map while moving).
  VolumeObjectChange UpdateVolume(LoadedScene& scene, size_t index,
                                  const VolumeObjectOptions& options, bool preview = false);
  // The same for a depth object or visual hull (ibr::UpdateDepthObjectKind):
  // the pass takes the options, the maps stay uploaded.
  void UpdateDepthObject(LoadedScene& scene, size_t index, const DepthObjectOptions& options);
  // Times object `index`'s pass was built (1 after the constructor).
  int PassBuilds(size_t index) const;
  // Object `index`'s pass (its kind's accessors read what the last frame
  // counted: ibr::VolumePassOf, ibr::DisplacedRendererOf).
  const ObjectPass& object_pass(size_t index) const;

 private:
  struct Built {
    std::unique_ptr<ObjectPass> pass;
    glm::dmat4 world_from_object{1.0};  // LoadedObject::world_from_object
    int builds = 1;                     // times the pass was built
  };
  render::ProgramCache* programs_;
  capture::Bounds bounds_;
  std::vector<Built> passes_;
  std::optional<render::RenderTarget> target_;  // the frame target, resized per view
};

// The one writer of rendered datasets: every view of `views` drawn by
// `renderer` (one warm-up frame first) into `out`, a dataset directory
// (color/NAME.png, depth/NAME.exr camera z with 0 where empty, mask/NAME.png,
// dataset.json with the cameras, `bounds` if set and `depth_units`), staged
// so a failure leaves nothing behind. One progress line per view through
// `progress`, ending with what `measure` (if set) returns for that view's frame.
struct SceneRenderStats {
  std::vector<double> frame_ms;        // per view: draw + readback + composite
  std::vector<int64_t> object_pixels;  // per view: covered pixels
  std::vector<std::string> passes;     // SceneRenderer::PassNames()
};
struct DatasetManifest {
  std::optional<capture::Bounds> bounds;
  std::string depth_units = "scene units";
  bool normals = false;  // also normal/NAME.exr (world normals; the passes that write them)
};
SceneRenderStats RenderViewsToDataset(
    SceneRenderer& renderer, const std::vector<NamedView>& views, const std::filesystem::path& out,
    const DatasetManifest& manifest, const std::function<void(const std::string&)>& progress = {},
    const std::function<std::string(const NamedView&, const render::Frame&)>& measure = {});
// Every camera of the scene (RenderViewsToDataset, the scene's bounds).
SceneRenderStats RenderSceneToDataset(render::ProgramCache& programs, const LoadedScene& scene,
                                      const std::filesystem::path& out,
                                      const std::function<void(const std::string&)>& progress = {});

}  // namespace ibr
