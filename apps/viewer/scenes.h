// The scenes `ibr view` shows: a dataset's depth object or visual hull (the
// one-object scene `ibr render DATASET` draws) and a scene file (as `ibr
// render SCENE.json` draws it), both through ibr::SceneRenderer. Both draw
// from ViewCameraOf, the camera `ibr render --cameras` reads from the file
// viewer::CamerasOf describes, so a frame at rest is the frame `ibr render`
// writes from that camera.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "apps/viewer/gizmo.h"
#include "apps/viewer/transfer_function_panel.h"
#include "apps/viewer/viewer.h"
#include "ibr/depth_object.h"
#include "ibr/image_maps.h"
#include "ibr/scene_renderer.h"
#include "ibr/views.h"
#include "render/gl/shader_program.h"
#include "scene/scene.h"

namespace viewer {

// The view `ibr render --cameras FILE` renders, FILE holding CamerasOf(camera).
ibr::ViewCamera ViewCameraOf(const FrameCamera& camera);

// A dataset's depth object or visual hull with `options` (those `ibr render`
// takes from the same flags).
std::unique_ptr<Scene> MakeDatasetScene(const ibr::DepthObjectOptions& options, ibr::MapSet maps,
                                        std::string name);

// A scene file: every enabled object drawn by ibr::SceneRenderer into its
// frame target (the headless path of `ibr render SCENE.json`). The panel
// lists the objects and passes and shows each deform and volume object's
// cheap-to-change options as controls; a change goes to
// SceneRenderer::UpdateDeform / UpdateVolume, which rebuild only what it
// invalidates and reject invalid options (the error shows in the panel).
class SceneFileScene : public Scene {
 public:
  // Needs a current context (captures render, passes build).
  explicit SceneFileScene(const scene::Scene& file);

  std::string Title() const override { return title_; }
  glm::vec3 Centre() const override { return centre_; }
  float Radius() const override { return radius_; }
  bool DrawControls() override;
  const render::RenderTarget& Render(const FrameCamera& camera) override;
  std::string Status() const override;
  // The first deform object's first deformation amount, else the first
  // volume effect's main parameter, over its slider's range.
  bool DragParameter(double t) override;
  // Rebuilds the distance fields moving updates kept short (taking a field
  // built in the background where it serves) and resamples the preview maps
  // of volumes.
  void Settle() override;
  // Installs a background field that finished while the scene moves.
  bool Poll() override;

  // The gizmo on the selected deform object's box, or a peeled volume's
  // map (apps/viewer/gizmo.h); keys: T translate, R rotate, S scale, G hide
  // or show, N the next object with a gizmo.
  // Control + left drag: window/level of the gizmo's volume, else the first
  // volume's (apps/viewer/transfer_function_editor.h's DragWindowLevel).
  bool PointerPress(const FrameCamera& camera, const glm::dvec2& pixel, int mods) override;
  bool PointerDrag(const FrameCamera& camera, const glm::dvec2& pixel) override;
  void PointerRelease() override;
  bool Key(int key) override;
  std::vector<OverlayLine> Overlay(const FrameCamera& camera) const override;
  scene::Scene EditedScene(const FrameCamera& camera) const override;

  // The scene as loaded and edited so far (ibr::RenderSceneToDataset of it
  // renders what `ibr render` renders for a file with these options).
  const ibr::LoadedScene& loaded() const { return loaded_; }
  render::ProgramCache& programs() { return programs_; }

 private:
  bool DeformControls(size_t index);
  bool VolumeControls(size_t index);
  // A deform object's new options while moving: a field the displacement
  // outgrows is rebuilt only in Settle.
  void UpdateDeformWhileMoving(size_t index, const ibr::DeformObjectOptions& options);
  // After an update of object `index`: drops a used build; starts one for a
  // deferred field, or when the deformation moved (a drag starts) and the
  // field does not reach as far as the sliders can take it, unless one runs
  // that could serve it.
  void FollowBuild(size_t index, bool deferred, bool deformation_moved);
  // The largest displacement object `index`'s deformation reaches with its
  // sliders at their ends (normalised units): a field reaching that far
  // serves any slider drag (cached per deformation kinds and box).
  double ReachForDrags(size_t index);
  // Objects with a gizmo: deform objects, volumes with a peel.
  bool HasGizmo(size_t index) const;
  // The object's box, knife and peel as the gizmo sees them.
  GizmoBox GizmoBoxOf(size_t index) const;
  // A volume's peel angle (radians) while its flap edge is dragged.
  bool DragVolumePeel(size_t index, double angle);
  // Object `index`'s transfer-function editor, made on first use (its
  // histogram counts the volume once).
  struct TransferSlot {
    TransferEditor editor;
    Histogram histogram;
    TransferPanelState panel;
  };
  TransferSlot& TransferOf(size_t index);
  // The editor's function to the volume's pass (options.transfer).
  void ApplyTransfer(size_t index);

  scene::Scene file_;  // as read: what EditedScene rewrites

  std::string title_;
  render::ProgramCache programs_;
  ibr::LoadedScene loaded_;
  ibr::SceneRenderer renderer_;
  std::vector<std::string> objects_;
  std::string error_;              // the last rejected change
  std::vector<size_t> unsettled_;  // deform objects whose field a drag outgrew or moved
  // Per unsettled deform object: its field being built on a worker thread
  // (issue 36), started when a drag defers the field; builds no longer
  // wanted finish in `stale_` (a build cannot be cancelled, and waiting for
  // one would hold the frame).
  std::map<size_t, std::unique_ptr<ibr::DeformFieldBuild>> builds_;
  std::vector<std::unique_ptr<ibr::DeformFieldBuild>> stale_;
  struct ReachHint {
    core::DeformationSum kinds;  // the terms at their slider ends
    glm::dmat4 placement{0.0};
    double reach = 0;
  };
  std::map<size_t, ReachHint> reach_hints_;
  glm::vec3 centre_{0};
  float radius_ = 1;
  // The gizmo: the deform object it is on, its mode, and a drag in progress
  // (the handle, where and on what box it started).
  std::optional<size_t> gizmo_object_;
  GizmoMode gizmo_mode_ = GizmoMode::kTranslate;
  bool gizmo_shown_ = true;
  std::optional<int> drag_handle_;
  glm::dvec2 drag_from_{0.0};
  GizmoBox drag_box_;
  GizmoPlacement drag_start_;
  std::map<size_t, TransferSlot> transfers_;
  // A window/level drag in progress: the volume, where it started.
  std::optional<size_t> window_drag_;
  WindowLevel window_start_;
};

}  // namespace viewer
