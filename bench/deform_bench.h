// `ibr bench deform`: what the deform pass (Correa, Silver, Chen 2007;
// render/passes/deform_pass.h) costs and how accurate it is, measured on
// meshes normalised into the unit cube centred at the origin (longest side
// 1). `ibr deform` itself is ibr::RenderDeform (ibr/jobs/deform_job.h).
#pragma once

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "bench/report.h"
#include "core/deform_reference.h"
#include "core/deformation.h"
#include "core/distance_field.h"
#include "core/image.h"
#include "ibr/deform_object.h"
#include "ibr/jobs/deform_job.h"
#include "render/gl/shader_program.h"
#include "render/passes/deform_pass.h"
#include "render/passes/pass.h"

namespace bench {

// The per-pixel outcome counts of `ibr deform`'s frames (ibr/jobs/deform_job.h),
// which the deform bench tabulates.
using DeformOutcomes = ibr::DeformOutcomes;
using ibr::CountDeformOutcomes;

// The solid knife cut of the bench's cut modes, its accuracy sweep and the
// report's gallery (Correa, Silver, Chen 2007, eq. 6): a knife of amount 0.15
// and width 0.6 (box units), CutMode::kSolid in the pass.
core::Deformation KnifeCut();

// A mesh file loaded and normalised (ibr::NormaliseMesh: the unit cube at
// the origin), and the deformation box around it: its bounds grown by 0.05.
core::TriangleMesh LoadNormalisedMesh(const std::filesystem::path& mesh_file);
core::Placement AroundMesh(const core::TriangleMesh& mesh);

// The solid knife cut through a mesh of the gallery and of the bench's
// accuracy sweep: the mesh normalised, the deformation box its bounds grown
// by 0.05, KnifeCut sampled at 64 nodes per axis. Built in place (members
// refer to each other).
struct KnifeCutScene {
  explicit KnifeCutScene(const std::filesystem::path& mesh_file);
  KnifeCutScene(const KnifeCutScene&) = delete;
  KnifeCutScene& operator=(const KnifeCutScene&) = delete;
  // The pass's inputs with `sdf` (DeformDistanceField over the box, grow).
  render::DeformInputs Inputs(const core::DistanceField& sdf) const;
  // The double sphere tracer of the solid cut (refers to this scene).
  core::DeformReference Reference() const;

  core::TriangleMesh mesh;  // normalised
  core::Placement placement;
  core::DeformationSum deformation;
  core::MeshDistance distance;  // exact, of `mesh`
  double grow = 0.0;            // the largest displacement, normalised units
  core::DeformationTexture texture;
};

// The distance field the deform pass samples: over `box` (normalised units)
// grown by `grow` (the largest displacement: samples land up to that far
// out) and two grid steps of the box's diagonal (the normals' central
// differences), `resolution` samples along the longest axis.
core::DistanceField DeformDistanceField(const core::MeshDistance& distance, const core::Box3d& box,
                                        double grow, int resolution);

// A square pinhole view of a normalised mesh (world = normalised units),
// principal point at the image centre.
struct DeformPinholeView {
  glm::dmat4 cam_from_world{1.0};  // rigid
  double focal_px = 1.0;
  int size = 0;  // width = height, pixels
  // The pass's view: clip range 0.05..10 normalised units.
  render::ViewSetup Setup() const;
};
// The oblique view of the gallery's cut and of the bench's accuracy sweep:
// 2.4 from the origin at azimuth -50 degrees about +y (OBJ up) and elevation
// 35 degrees, looking at the origin, a 34 degree field of view.
DeformPinholeView DeformObliqueView(int size);

// The truth of the deform pass in one view: the double sphere tracer of
// core/deform_reference.h traced through every pixel centre inside the
// deformation box (`placement`; the mesh lies inside it, so nothing is seen
// outside).
struct DeformReferenceFrame {
  core::ImageF depth;    // camera z (normalised units); 0 = no hit
  core::Image8 color;    // RGBA: head-light shading of the reference normal, cut faces tinted
  core::Image8 classes;  // 0 no hit, 1 the surface, 2 a cut face
};
DeformReferenceFrame TraceDeformReference(const core::DeformReference& reference,
                                          const core::Placement& placement,
                                          const DeformPinholeView& view);

// The orbit view of the bench's workloads as a pinhole (DeformPinholeView):
// `distance` (2.6) from the origin at `azimuth_deg` about +y and `elevation_deg`, looking
// at the origin, a 34 degree field of view (RunDeform's default view of a
// normalised mesh).
DeformPinholeView DeformOrbitView(int size, double azimuth_deg = 30.0, double elevation_deg = 20.0,
                                  double distance = 2.6);

// The share of pixels whose class (no hit, surface, cut face) agrees between
// a deform pass frame and the reference, outside a one-pixel band around the
// reference's class boundaries (where a pixel centre and its footprint may
// see different classes); as deform_pass_test checks it.
struct DeformClassAgreement {
  int64_t compared = 0, agree = 0, band = 0;
  double Fraction() const { return compared > 0 ? double(agree) / double(compared) : 0.0; }
};
DeformClassAgreement CompareDeformClasses(const render::Frame& frame,
                                          const DeformReferenceFrame& truth);

}  // namespace bench

namespace bench {

// `ibr bench deform`: the cost of deformation and cut shaders (Correa,
// Silver, Chen 2007, sec. 6.2, Table 1 and Fig. 7 analogues) on Spot,
// fandisk, the cow and the capped Stanford bunny (normalised, one orbit view):
//  - per mesh and mode (continuous = twist; cut = solid knife by the paper's
//    two-field search of sec. 5.1.2 without empty-space skipping; cut_skip =
//    the same with skipping; cut_csg = the solid knife by the CSG field, no
//    skipping; all with the pass's default skipping by the object's distance
//    field; paper_continuous, paper_cut, paper_cut_skip = the paper's own
//    shader: the first three without that skipping, as sec. 6.2 has only the
//    cut's) and region scale: ms per frame (median) against the deformed
//    region's relative screen area a (pixels where a ray was cast / all
//    pixels), and the ray stage's share (the frame minus the mesh stage,
//    measured per scale as the continuous frame minus its ray stage alone);
//  - the paper's weighted average sum(a t) / sum(a) per mesh and mode, the
//    ratios to continuous (paper_*: to paper_continuous; frames and ray
//    stages), a least-squares line of ms
//    against a with its R^2, and the spread across meshes of the fitted ms at
//    one area (frames and ray stages);
//  - the distance-field build time per resolution (ours: exact within the
//    band, bench/openvdb_peer.py: OpenVDB's createLevelSetFromPolygons with
//    the same voxel size and half width, timed in Python) and their ratio.
//  - what accuracy costs: Spot cut by the solid knife (KnifeCut) from the
//    oblique view (DeformObliqueView), ms per frame against the error of the
//    pass's depth and silhouette with respect to the double sphere tracer
//    (TraceDeformReference, traced once), sweeping one knob at a time: the
//    distance field's resolution (fixed step of 1 voxel) and, at resolution
//    128, the step of each step policy (fixed, threshold, Jacobian) in voxels;
//    and the two implicits at 128: the distance field against the depth-map
//    cube (sec. 6.1): bytes, build time, ms per frame, IoU and depth error.
struct DeformBenchOptions {
  std::filesystem::path shared_data = "../shared/data";  // meshes/*.obj
  std::filesystem::path csv;                             // the frame table
  std::filesystem::path out;                             // plots, the other tables, the peer's mesh
  int size = 512;                                        // image width = height, pixels
  // 128 px, two meshes, two region scales, SDF 32/64; accuracy: SDF 32/128,
  // steps of 1 and 4 voxels.
  bool quick = false;
  bool peer = true;  // time OpenVDB's Python binding beside our distance field
  // Only the distance-field table (RunDeformSdfBench, no GL).
  bool sdf_only = false;
  // Only the wedge, forward-mesh and spread workloads (no region sweep,
  // distance-field builds or accuracy sweep).
  bool workloads_only = false;
  void Check() const;
};

// The honest cut workload (Correa 2007 sec. 3 and 6.2; issue 35): a wedge
// cut-away (core::DeformationKind::kWedge: D = 0, the alpha a signed
// distance) in a box enclosing the object, so no face of the box meets it,
// opened towards the orbit view so that a large share of the rays meet the
// cut's material and march through it. Baseline: the same D without its
// alpha (no cut). Figures from interleaved rounds (per-round ratios, their
// median and distribution-free 95 % interval).
struct DeformWedgeFigures {
  std::string mesh;
  double opening_rad = 0.0, bottom = 0.0;  // the wedge's amount and width
  // cut_skip / baseline frame time: median of per-round ratios, 95 % interval.
  double ratio = NAN, ratio_lo = NAN, ratio_hi = NAN;
  double csg_ratio = NAN;  // cut_csg / baseline, the same way
  // The paper's shader (no skipping by the object's distance):
  // paper_cut_skip / paper_baseline, the same way.
  double paper_ratio = NAN;
  // The cut_skip shader on the baseline's texture (no alpha: the same rays
  // and samples) over the baseline: what the search's shader costs a sample.
  double shader_overhead = NAN;
  // Samples per ray: baseline, cut (no skipping), cut_skip.
  double samples_baseline = NAN, samples_cut = NAN, samples_skip = NAN;
  // The share of the cut's extra samples (cut - baseline) the skip removes, %.
  double skip_removes_percent = NAN;
  // Cast rays with a rejected crossing (their surface hit lies in the cut)
  // in the cut_skip frame, and the same share computed on the CPU from the
  // baseline frame's hit points and the analytic alpha (a check).
  double ray_fraction = NAN, ray_fraction_cpu = NAN;
  // cut_skip against the double reference: pixel classes and depth.
  double agree_fraction = NAN, p95_depth_error = NAN;
  // "wedge: cut_skip/baseline R, skip removes P % of the cut's extra
  // samples, ray fraction F"
  std::string Line() const;
};

// The peer mode forward-mesh: the continuous twist of the bench applied to
// the vertices of the mesh subdivided `level` times (1:4 midpoint, the same
// flat surface) by its forward map and rasterised by the mesh pass, beside
// the ray pass of the same twist, both against the double reference, same
// view and run.
struct DeformForwardFigures {
  std::string mesh;
  double ray_ms = NAN, ray_p95 = NAN;  // the ray pass (continuous twist)
  // The coarsest level whose p95 depth error is at most the ray pass's (-1:
  // none of the levels run), its triangles and ms.
  int equal_level = -1;
  int64_t equal_triangles = 0;
  double equal_ms = NAN, equal_p95 = NAN;
  // The mesh's ms at exactly the ray pass's p95, log-log between levels
  // (extrapolated beyond the levels run).
  double interpolated_ms = NAN;
  std::string Line() const;
};

// Spread: one shape (the capped Stanford bunny) at several tessellations
// (meshoptimizer's simplifier), the same twist, box, view and field
// resolution, in interleaved rounds. Per mesh: the ray stage alone over the
// finest mesh's in the same round, and the deform pass's mesh stage (timed
// alone: draw_rays off) over a plain mesh pass of the same mesh; medians of
// per-round ratios with 95 % intervals.
struct DeformSpreadFigures {
  double ray_spread = NAN;           // max / min over meshes of the ray-stage medians
  double mesh_over_plain_max = NAN;  // the largest mesh-stage / plain median
  int rounds = 0;
  size_t min_triangles = 0, max_triangles = 0;  // the tessellations' range
  std::string Line() const;
};

// Correa 2007 Fig. 3 (b)-(d): a narrow Gaussian pull (amplitude 0.5, width
// 0.015 of the box) raises a column thinner than a step from the flat top
// of a box mesh up through the deformation box's top face, seen from the
// side and zoomed onto its upper part. Per step
// policy of the ray core (fixed, threshold 0.04 as the figure, Jacobian:
// eq. 4), at a base step of one voxel of a 64^3 distance field: rays that
// miss (the double reference hits, the pass finds nothing), pixels whose
// class (nothing, surface, cut face) differs from the reference, both
// outside a one-pixel band around the reference's class boundaries, the
// pixels compared, samples per ray and ms per frame.
struct DeformPullFigures {
  struct Policy {
    std::string name;  // render::RayStepPolicyName
    int64_t misses = 0, wrong = 0, compared = 0;
    double samples_per_ray = NAN, ms = NAN;
  };
  std::vector<Policy> policies;  // fixed, threshold, jacobian
  const Policy* Find(const std::string& name) const;
  // "narrow pull (Fig. 3): rays that miss the spike: fixed N, threshold N,
  // jacobian N of C compared pixels (...)"
  std::string Line() const;
};

struct DeformBenchResult {
  // workload (sweep: the region-scale sweep; wedge; forward), mesh,
  // triangles, mode, series, region_scale, area_fraction, ms, ray_ms (the
  // frame minus the mesh stage), samples_per_ray, rejected_per_ray,
  // cut_ray_fraction (cast rays with a rejected crossing; modes that reject
  // only), mesh_ms (the mesh stage at that scale), mesh_both_sides_ms
  // (continuous rows: the mesh stage with cull_back_faces off, the culling's
  // baseline), p95_depth_error and agree_fraction (wedge and forward rows:
  // against the double reference; mesh sizes)
  Table frames;
  // mesh, mode, weighted_ms, over_continuous, slope_ms, intercept_ms, r2,
  // ray_weighted_ms, ray_over_continuous (and one "across meshes" row per mode)
  Table summary;
  // mesh, resolution, builder (ours, openvdb: C++, openvdb_python), series,
  // seconds, queries_or_active, then accuracy against CGAL (bench/openvdb_sdf.h):
  // band_samples, missing_band_nodes, max/p95_error_voxels, sign_samples, sign_errors
  Table sdf;
  // mesh, size_px, knob ("resolution" or "step"), value (its setting), mode
  // (step policy), resolution, step_voxels, ms_per_frame, samples_per_ray,
  // silhouette_iou, wrong_pixels, mean_depth_error, p95_depth_error (depth
  // errors in mesh sizes: the normalised mesh's longest side is 1).
  Table accuracy;
  // The two implicits on the accuracy sweep's cut Spot at resolution 128
  // (fixed step of one voxel / texel): mesh, size_px, implicit (sdf or
  // depth-cube), resolution, bytes (GPU texture memory), build_seconds,
  // ms_per_frame, samples_per_ray, silhouette_iou, wrong_pixels,
  // mean_depth_error, p95_depth_error (mesh sizes, against the tracer).
  Table implicits;
  // The workloads of issue 35 (their rows are also in `frames`, column
  // workload "wedge" and "forward"):
  DeformWedgeFigures wedge;
  DeformForwardFigures forward;
  // mesh, triangles, rounds, ray_ms (median), ray_over_scan, its _lo/_hi,
  // mesh_stage_ms, plain_mesh_ms, mesh_over_plain, its _lo/_hi, samples_per_ray
  Table spread = Table(std::vector<std::string>{});
  DeformSpreadFigures spread_figures;
  // Fig. 3's narrow pull: policy, size_px, field_resolution, step_voxels,
  // misses, wrong_pixels, compared_pixels, samples_per_ray, ms_per_frame.
  Table pull = Table(std::vector<std::string>{});
  DeformPullFigures pull_figures;
};

// The three workloads (bench/deform_workloads.cc), at `size` pixels and
// distance fields of `field_resolution`; the wedge's and the forward mesh's
// rows are appended to `frames` (the frames table's columns).
DeformWedgeFigures RunDeformWedge(render::ProgramCache& programs, const DeformBenchOptions& options,
                                  int size, int field_resolution, Table& frames);
DeformForwardFigures RunDeformForwardMesh(render::ProgramCache& programs,
                                          const DeformBenchOptions& options, int size,
                                          int field_resolution, Table& frames);
// Fig. 3's narrow pull (DeformPullFigures) at `size` pixels: its table
// (DeformBenchResult::pull), its figures into `figures`.
Table RunDeformNarrowPull(render::ProgramCache& programs, int size, DeformPullFigures& figures);
// The spread table (DeformBenchResult::spread); its figures into `figures`.
Table RunDeformSpread(render::ProgramCache& programs, const DeformBenchOptions& options, int size,
                      int field_resolution, DeformSpreadFigures& figures);

DeformBenchResult RunDeformBench(render::ProgramCache& programs, const DeformBenchOptions& options);
// The tables as CSV (frames at options.csv, the others beside it in out:
// deform_summary.csv, deform_sdf.csv, deform_accuracy.csv, deform_implicit.csv)
// and the gnuplot PNGs in out.
// The distance-field table alone (DeformBenchResult::sdf's rows).
Table RunDeformSdfBench(const DeformBenchOptions& options);

void WriteDeformBench(const DeformBenchResult& result, const DeformBenchOptions& options);

}  // namespace bench
