// `ibr deform`: a mesh deformed and cut by the deform pass (Correa, Silver,
// Chen 2007; render/passes/deform_pass.h) as a one-object scene drawn by
// ibr::SceneRenderer from an orbit view or a dataset's cameras into a PNG or
// a dataset folder (ibr::RenderViewsToDataset). The mesh is normalised
// into the unit cube centred at the origin (longest side 1), so regions,
// thicknesses and the threshold are in those units.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "ibr/deform_object.h"
#include "ibr/views.h"
#include "render/gl/shader_program.h"
#include "render/passes/pass.h"

namespace ibr {

struct DeformRenderOptions {
  std::filesystem::path mesh;  // OBJ/PLY/... (assimp)
  // The deformation, its box, the cut, the ray's steps, the distance field
  // (ibr/deform_object.h: flags -> DeformObjectOptionsFrom).
  DeformObjectOptions object;
  int size = 512;             // image width = height, pixels
  double azimuth_deg = 30.0;  // camera orbit about +y (OBJ up)
  double elevation_deg = 20.0;
  // A dataset whose cameras to render from instead of the orbit view (its
  // world frame is the mesh file's, as `ibr capture` writes it).
  std::filesystem::path cameras;
  // FILE.png: one colour PNG, camera z as <stem>.depth.exr beside it (one
  // view only); otherwise a dataset folder as `ibr render` writes (colour,
  // camera z, mask, normals; dataset.json), staged.
  std::filesystem::path out;
  void Check() const;
  bool WritesDataset() const { return out.extension() != ".png"; }
};

// Per-pixel outcome counts of one frame (render/passes/deform_pass.h bits).
struct DeformOutcomes {
  int64_t mesh_pixels = 0, hit_pixels = 0, cut_face_pixels = 0, exited_pixels = 0, early_pixels = 0;
  int64_t rays = 0;           // pixels where a ray was cast
  double mean_samples = 0.0;  // field samples per cast ray
  // Crossings rejected per cast ray (a surface hit inside the cut, a cut
  // boundary outside the body: sec. 5.1.2), and the rays with at least one.
  double mean_rejected = 0.0;
  int64_t rejecting_rays = 0;
  void Add(const DeformOutcomes& other);
};
DeformOutcomes CountDeformOutcomes(const render::Frame& frame);

struct DeformViewReport {
  std::string name;
  DeformOutcomes outcomes;
};

struct DeformRenderReport {
  double sdf_seconds = 0.0;  // the implicit's build time
  glm::ivec3 sdf_size{0};    // 0 with the depth cube
  int cube_size = 0;         // the depth cube's map size, 0 with the distance field
  int64_t implicit_bytes = 0;
  int64_t distance_queries = 0;
  double max_displacement = 0.0;  // normalised units
  std::vector<DeformViewReport> views;
  DeformOutcomes total;   // over every view
  double frame_ms = 0.0;  // median frame time of the first view after warm-up
};

// Loads, normalises, builds the distance field and the deformation texture,
// renders every view and writes the outputs (staged: nothing partial on error).
DeformRenderReport RenderDeform(render::ProgramCache& programs, const DeformRenderOptions& options);

// The orbit of `ibr deform` and of the deform bench (ibr::OrbitCameraView):
// a 34 degree field of view, `distance` world units from the centre (`ibr
// deform`: 2.6 longest sides of the mesh), `azimuth_deg` about +y (OBJ up)
// from +z and `elevation_deg` above the horizon.
OrbitCamera DeformOrbit(double azimuth_deg, double elevation_deg, double distance = 2.6);

// What `ibr deform` prints: the implicit, the largest displacement, each
// view's pixel outcomes and the frame time, one line each; `out` is where
// the images went.
std::string DeformReportText(const DeformRenderReport& report, const std::string& out);

}  // namespace ibr
