// A mesh deformed and cut by the deform pass (Correa, Silver, Chen 2007;
// render/passes/deform_pass.h) as plain CPU data, shared by `ibr deform`, the
// deform bench (bench::RunDeform) and deform objects in scene files
// (ibr/scene_renderer.h): options (flags or scene keys, as scene::Settings)
// -> DeformObjectOptions -> MakeDeformObject -> render::DeformPass.
//
// The pass works in normalised units: the mesh centred at the origin, its
// longest side 1 (regions, widths, thicknesses and the threshold are in those
// units); object_from_norm carries them back to the mesh file's frame, the
// object frame of a scene's deform object and the world of `ibr deform`.
#pragma once

#include <glm/glm.hpp>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/deformation.h"
#include "core/distance_field.h"
#include "core/mesh.h"
#include "render/passes/deform_pass.h"
#include "scene/scene.h"

namespace ibr {

struct DeformObjectOptions {
  core::DeformationSum deformation;  // default: one twist (DeformObjectOptionsFrom)
  // Region box in normalised units; empty = the mesh's bounds grown by 0.05
  // (along +x by the spread of slices, period / (period - gap)).
  std::optional<core::Box3d> region;
  glm::dvec3 rotation_deg{0.0};  // placement: Euler angles about the region's centre
  double scale = 1.0;            // placement: scale about the region's centre
  glm::dvec3 translation{0.0};   // placement: translation (normalised units)
  render::DeformPassOptions pass;
  // Distance-field samples along the longest axis; with the depth cube
  // (pass.implicit) the size of its six maps in pixels.
  int sdf_resolution = 128;
  int deformation_resolution = 64;  // deformation texture nodes per axis
  bool cap_holes = false;           // fill the boundary loops of an open mesh
  // How far (normalised units) the distance field reaches beyond the
  // deformation box, at least: the field covers the box grown by
  // max(sdf_reach, the deformation's largest displacement) (warped samples
  // land up to that far out). Empty = the largest displacement alone.
  // UpdateDeformObject sets it when it keeps a field that reaches further
  // than the new deformation needs, so the options still make the same data.
  std::optional<double> sdf_reach;

  // InputError on values MakeDeformObject cannot use: the deformation's and
  // the pass's Check(), a placement scale <= 0, resolutions outside 8..512
  // (field) and 2..256 (deformation texture), a negative or non-finite reach.
  void Check() const;
  // Field by field (tests/ibr/object_kind_registry_test: the CLI and a scene agree).
  bool operator==(const DeformObjectOptions&) const = default;
};

// Default amount and width per kind (core::kDeformationTable).
void SetDeformationDefaults(core::Deformation& deformation);

// A deformation's box in its parent box (Deformation::parent_from_box) from
// "tx,ty,tz[,rx,ry,rz[,scale]]": translation in parent box units, Euler
// angles in degrees (x, then y, then z) and a scale about the box's centre.
// InputError naming `where` on a wrong count or a scale <= 0.
glm::dmat4 BoxPlacement(const std::vector<double>& numbers, const std::string& where);

// The deformations a settings bag names, one vocabulary for deform and
// volume objects (core::kDeformationTable):
//   deformation   NAME or a comma list ("none": no deformation); `fallback`
//                 when absent ("effect" is read as an alias)
//   amount, width a number or a comma list, one per deformation (defaults
//                 from the table)
//   deformations  instead of the three above: a JSON list of
//                 {"name", "amount", "width", "placement"}, each with its own
//                 placement (BoxPlacement; a string or a list of numbers):
//                 composite maps, Correa 2006 Fig. 5, eq. 9-10
//   placement     with `placement_key` (volumes): BoxPlacement of each of the
//                 deformations named by `deformation` (a deform object's
//                 `placement` moves its region instead: DeformObjectOptionsFrom)
// Errors name the value's `where`.
std::vector<core::Deformation> DeformationsFrom(const scene::Settings& settings,
                                                const std::string& fallback,
                                                bool placement_key = false);

// Keys (every one optional; errors name the value's `where`):
//   deformation, amount, width, deformations  DeformationsFrom (summed)
//   cut          none|hollow|solid|thick:T
//   region       "x0,y0,z0,x1,y1,z1" (normalised units)
//   placement    "tx,ty,tz[,rx,ry,rz[,scale]]" about the region's centre
//   step         fixed|threshold:T|jacobian;  step_voxels  base step (voxels)
//   skip         true/false (empty-space skipping in the cut, sec. 6.2)
//   implicit     sdf|depth-cube (the distance field, or sec. 6.1's depth-map cube)
//   resolution   distance-field samples along the longest axis, or the depth
//                cube's map size in pixels (8..512)
//   cap_holes    true/false
//   reach        the distance field's reach beyond the box (normalised units,
//                >= 0; sdf_reach)
DeformObjectOptions DeformObjectOptionsFrom(const scene::Settings& settings);

// Everything a render::DeformPass needs (Inputs() refers to the members:
// keep the object where it is while a pass built from it lives).
struct DeformObjectData {
  core::TriangleMesh mesh;  // normalised
  // CappedMesh of the mesh when --cap-holes filled holes (the pass draws it
  // instead of `mesh`); empty otherwise.
  std::optional<core::TriangleMesh> capped;
  glm::dmat4 object_from_norm{1.0};  // centre + longest * normalised
  core::Placement placement;         // the deformation box (normalised units)
  double max_displacement = 0.0;     // normalised units
  core::DistanceField sdf;           // DeformImplicit::kSdf (empty otherwise)
  render::DepthCube depth_cube;      // DeformImplicit::kDepthCube (empty otherwise)
  core::DeformationTexture texture;
  // The deformation box the distance field was built over (its extent
  // follows the box): differs from `placement` while a moved box's field is
  // deferred (UpdateDeformObject's defer_reach).
  core::Placement field_placement;
  double sdf_seconds = 0.0;  // the implicit's build time (distance field or depth cube)
  double sdf_reach = 0.0;    // the distance field's reach beyond the box (normalised units)
  int implicit_builds = 0;   // times the implicit was built (1 after MakeDeformObject)
  // The implicit's GPU memory: the R32F field, or the depth cube's six maps.
  int64_t ImplicitBytes() const;
  // What the frame can hold (normalised units): the mesh and the deformation
  // box grown by the largest displacement.
  core::Box3d norm_bounds;
  // The mesh the pass rasterises outside the box.
  const core::TriangleMesh& Drawn() const { return capped ? *capped : mesh; }
  render::DeformInputs Inputs() const { return {&Drawn(), &sdf, &texture, placement, &depth_cube}; }
};

// Where `distance` filled holes (--cap-holes): its closed mesh (welded, holes
// capped, outward-oriented) with area-weighted normals, which the deform pass
// rasterises and the depth cube renders instead of the open mesh, so that the
// rasterised part and the ray-cast implicit are one closed surface and no
// hole shows the inside beside a capped field. Empty when nothing was capped.
std::optional<core::TriangleMesh> CappedMesh(const core::MeshDistance& distance);

// Normalises `mesh` (InputError naming `where` for a mesh without extent),
// places the deformation box, builds the implicit (the distance field,
// progress on stderr when `progress`; or the depth cube, which renders its
// maps: `programs` with a current context) and samples the deformation.
DeformObjectData MakeDeformObject(core::TriangleMesh mesh, const DeformObjectOptions& options,
                                  const std::string& where, bool progress = false,
                                  render::ProgramCache* programs = nullptr);

// What changing a deform object's options invalidated (UpdateDeformObject).
struct DeformObjectChange {
  bool implicit = false;     // the distance field or depth cube was rebuilt
  bool deformation = false;  // the deformation texture was resampled (and the
                             // largest displacement and norm_bounds recomputed)
  bool pass = false;         // the pass options differ (shader defines, uniforms)
  // The new displacement outgrew the field's reach but, asked to defer, the
  // field was kept (a moving frame of the viewer): the data differs from
  // MakeDeformObject(options) until an update without deferral rebuilds it.
  bool implicit_deferred = false;
  bool Any() const { return implicit || deformation || pass; }
};

// A distance field built on a worker thread (issue 36: the exact frame soon
// after a drag that outgrew or moved the field): CPU work alone
// (core::MeshDistance, core::BuildDistanceField; no GL off the main thread),
// the field a rebuild by UpdateDeformObject(data, ..., options) would make
// now: over data.placement, reaching max(options.sdf_reach, 1.5 x
// data.max_displacement). UpdateDeformObject installs it (`prebuilt`) in
// place of a rebuild when it serves the update (Serves), so the field equals
// what MakeDeformObject makes of the options the update ends with.
class DeformFieldBuild {
 public:
  // Starts the build (`threads` as core::DistanceFieldOptions::threads; 0 =
  // all). `data` stays alive through the pointer; depth-cube objects have
  // no field to build (IBR_CHECK).
  // `nice` > 0 lowers the worker's priority (Linux; per thread) so the
  // thread that renders keeps the CPU it needs.
  DeformFieldBuild(std::shared_ptr<const DeformObjectData> data, const DeformObjectOptions& options,
                   std::string where, int threads = 0, int nice = 0);
  ~DeformFieldBuild();  // waits for the worker: a build cannot be cancelled
  DeformFieldBuild(const DeformFieldBuild&) = delete;
  DeformFieldBuild& operator=(const DeformFieldBuild&) = delete;

  bool Ready() const;
  bool Used() const;  // installed by an update: nothing left to give
  // The field suits `options` on a box `placement` whose deformation moves
  // points up to `max_displacement`: the same box, field resolution and
  // capping, a reach at least the displacement (and at least the reach
  // options ask for).
  bool Serves(const DeformObjectOptions& options, const core::Placement& placement,
              double max_displacement) const;
  double reach() const { return reach_; }

 private:
  friend DeformObjectChange UpdateDeformObject(DeformObjectData&, const DeformObjectOptions&,
                                               DeformObjectOptions&, const std::string&,
                                               render::ProgramCache*, bool, DeformFieldBuild*);
  struct Worker;
  std::unique_ptr<Worker> worker_;
  core::Placement placement_;
  int resolution_ = 0;
  bool cap_holes_ = false;
  double reach_ = 0;
};

// Turns `data`, made by MakeDeformObject from `old_options`, into what it
// makes from `options` with the same mesh, rebuilding only what the change
// invalidates: the deformation's kinds, amounts, widths or texture resolution
// resample the deformation texture (cheap, milliseconds); the placement,
// implicit kind, field resolution, hole capping or reach rebuild the implicit
// (the distance field costs seconds), as does a deformation whose largest
// displacement outgrows the field's reach; a rebuilt field reaches 1.5 times
// as far as needed (so a slider dragged upwards rarely rebuilds it). A kept
// field's reach goes into options.sdf_reach, as does a rebuilt one's, so
// MakeDeformObject(options) makes the same data. Cut, step and skip options
// change the pass alone. options.Check() first (InputError naming `where`);
// on any error nothing changes. `defer_reach`: a field the displacement
// outgrows, or the field of a box the placement moved, is kept
// (change.implicit_deferred) unless something else asks for a rebuild; the
// same update without it then rebuilds the field. `prebuilt`: a field built
// in the background; where the update needs a new field and `prebuilt`
// serves it (and is ready, when deferring; else it is waited for), it is
// installed instead of a rebuild and options.sdf_reach set to its reach.
DeformObjectChange UpdateDeformObject(DeformObjectData& data,
                                      const DeformObjectOptions& old_options,
                                      DeformObjectOptions& options, const std::string& where,
                                      render::ProgramCache* programs = nullptr,
                                      bool defer_reach = false,
                                      DeformFieldBuild* prebuilt = nullptr);

// The depth-map cube (Correa 2007 sec. 6.1, render::DepthCube) of `mesh`:
// the six orthographic maps of the cube rig of `ibr capture` (CaptureMaps,
// capture::MakeRig "cube": the mesh's bounding cube grown by 5 %), `size`
// pixels square, rendered by the capture rasteriser. Needs a current context.
render::DepthCube MakeDepthCube(render::ProgramCache& programs, const core::TriangleMesh& mesh,
                                int size);

// Centres the mesh at the origin and scales its longest side to 1 (the
// normalised units); InputError naming `where` for a mesh without extent.
void NormaliseMesh(core::TriangleMesh& mesh, const std::string& where = "ibr deform");

// What a frame must hold (normalised units): the mesh and the deformation
// box, grown by the largest displacement.
core::Box3d DeformedBounds(const core::Box3d& mesh, const core::Box3d& box, double displacement);

// The deformation box (normalised units) and its placement.
core::Placement DeformPlacement(const DeformObjectOptions& options, const core::Box3d& mesh_bounds);

}  // namespace ibr
