// Image-based depth objects and visual hulls by slicing and the stencil
// buffer (Kautz-Seidel 2001, sec. 4 and 5), generalised to perspective maps
// and arbitrary registered cameras, with robust intersection and
// visibility-aware texturing.
//
// Stages: PrepareFrame() turns maps + view + options into FrameParams, every
// number the GPU uses, computed once on the CPU in float; the GPU passes
// (DepthObjectRenderer) and the CPU reference (verify/reference.h) both consume
// exactly these numbers, so they can agree pixel for pixel.
#pragma once

#include <glm/glm.hpp>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/enum_names.h"
#include "core/image.h"
#include "ibr/image_maps.h"
#include "render/cores/slice_buffer.h"
#include "render/cores/slicing.h"
#include "render/gl/render_target.h"
#include "render/gl/shader_program.h"
#include "render/passes/depth_object_gpu.h"
#include "render/passes/pass.h"

namespace ibr {

enum class Method {
  kDepthObject,  // intersection of the regions behind each map's depth (sec. 4)
  kVisualHull,   // intersection of the silhouette cones (sec. 5)
};
enum class Slicing {
  kOrthogonal,  // box-axis slices in the best direction (sec. 3.2, 4.1)
  kScreen,      // view-plane slices (sec. 3.3)
  kRay,         // one pass, a ray per pixel on the shared ray core (render/cores/ray_core.h)
};
// How the slice families (kOrthogonal, kScreen) are drawn; kRay ignores it.
enum class SlicePath {
  kExact,  // the paper's stencil passes, per slice and map, bit-exact to verify/reference.h
  kFast,   // every slice in one draw, the map loop in the shader, the depth test keeps
           // the front slice (ibr/depth_object_fast.cc)
};
enum class Texturing {
  kViewDependent,  // sec. 4.2's weights over the maps that saw the point (default)
  kVisibility,     // only maps that saw the point, cos^8 weights; VDT where none did
  kNone,           // grey, shaded
  kPaperBlend,     // the paper's VDT as blended in the map loop, no visibility test
};
// Points outside a map's image (or behind a pinhole map).
enum class OutsidePolicy {
  kPass,  // no constraint: a camera that did not see a region cannot carve it
  kFail,  // carved: the object must lie inside every camera's view
};
// Depth 0 (invalid) inside the silhouette (or everywhere when there is no mask).
enum class InvalidDepthPolicy {
  kEmpty,         // the paper's convention: displacement 0 is never drawn (sec. 3.2)
  kNoConstraint,  // a hole in a sensor / MVS map carves nothing
};

inline constexpr core::EnumName<Method> kMethodNames[] = {
    {Method::kDepthObject, "depth-object"},
    {Method::kVisualHull, "visual-hull"},
};
inline constexpr core::EnumName<Slicing> kSlicingNames[] = {
    {Slicing::kOrthogonal, "orthogonal"},
    {Slicing::kScreen, "screen"},
    {Slicing::kRay, "ray"},
};
inline constexpr core::EnumName<SlicePath> kSlicePathNames[] = {
    {SlicePath::kExact, "exact"},
    {SlicePath::kFast, "fast"},
};
inline constexpr core::EnumName<Texturing> kTexturingNames[] = {
    {Texturing::kViewDependent, "vdt"},
    {Texturing::kVisibility, "visibility"},
    {Texturing::kNone, "none"},
    {Texturing::kPaperBlend, "vdt-paper"},
};
inline constexpr core::EnumName<OutsidePolicy> kOutsidePolicyNames[] = {
    {OutsidePolicy::kPass, "pass"},
    {OutsidePolicy::kFail, "fail"},
};
inline constexpr core::EnumName<InvalidDepthPolicy> kInvalidDepthPolicyNames[] = {
    {InvalidDepthPolicy::kEmpty, "empty"},
    {InvalidDepthPolicy::kNoConstraint, "no-constraint"},
};
static_assert(core::EnumNamesUnique(kMethodNames) && core::EnumNamesUnique(kSlicingNames) &&
              core::EnumNamesUnique(kSlicePathNames) && core::EnumNamesUnique(kTexturingNames) &&
              core::EnumNamesUnique(kOutsidePolicyNames) &&
              core::EnumNamesUnique(kInvalidDepthPolicyNames));

Method MethodFromName(const std::string& name);    // "depth-object", "visual-hull"
Slicing SlicingFromName(const std::string& name);  // "orthogonal", "screen", "ray"
// "vdt", "visibility", "none", "vdt-paper"
Texturing TexturingFromName(const std::string& name);
// "auto" -> DepthObjectOptions::kAutoSlices, else a count in 1..16384.
int SliceCountFromName(const std::string& name);
std::string SliceCountName(int slices);  // "auto" or the count
std::string MethodName(Method m);
std::string SlicingName(Slicing s);
std::string TexturingName(Texturing t);
SlicePath SlicePathFromName(const std::string& name);  // "exact", "fast"
std::string SlicePathName(SlicePath p);

struct DepthObjectOptions {
  Method method = Method::kDepthObject;
  Slicing slicing = Slicing::kOrthogonal;
  // kExact (the default): the paper's stencil passes, mirrored bit for bit by
  // verify/reference.h. kFast: the same slices, map tests, colour sum and depth
  // in one draw per frame (ibr/depth_object_fast.cc); where orthogonal slices
  // are not crossed front to back along a ray (the eye between them) it keeps
  // the nearest accepted slice instead of the first drawn.
  SlicePath slice_path = SlicePath::kExact;
  // Slices through the box per frame (>= 1), or kAutoSlices. Depth
  // resolution is one slice spacing; 128-256 is the paper's range. kRay:
  // linear-search steps across the box's depth range (the screen slices'
  // spacing), then bisection. kAutoSlices (the default): sec. 3.4's rule
  // that the slices sample the depth maps as densely as they were taken, one
  // slice per depth texel along the slicing direction (AutoSliceCount).
  static constexpr int kAutoSlices = 0;
  int slices = kAutoSlices;
  // Robust intersection: keep pixels where at least N - k of the N maps agree
  // (0 = the paper's exact intersection). k >= N keeps the whole box.
  int robust_k = 0;
  Texturing texturing = Texturing::kViewDependent;
  // Default kPass: a camera that did not see a region has no evidence against
  // it (partial views, cropped objects; cf. Open3D issues #1441, #4359, where
  // carving outside the image silently removes object parts). Inside the cube
  // configuration's box the choice makes no difference.
  OutsidePolicy outside = OutsidePolicy::kPass;
  InvalidDepthPolicy invalid_depth = InvalidDepthPolicy::kEmpty;
  // Visual hulls: of two orthographic maps looking in exactly opposite
  // directions (the cube rig), use only the one facing the viewer: their
  // silhouettes are mirror images and carve the same cone (sec. 5: three maps
  // suffice in the cube configuration).
  bool hull_skip_opposite = true;
  // Visibility texturing: a map saw a point if |its z - its depth| <= this
  // (scene units); 0 = 4 slice spacings (the first slice inside lies up to
  // one spacing behind the surface, more along a grazing map's axis).
  double visibility_tolerance = 0;
  // Resolve pass: bisection steps refining each pixel's first surface between
  // the slice that finished it and the slice before (the same map tests), for
  // the output depth and the texturing; 0 = the slice position itself (the
  // paper's result). The stencil/colour accumulation is unaffected.
  // 0..render::kMaxRayRefineSteps (the ray core refines).
  int refine_steps = 6;
  // kRay: empty-space skipping (ibr/empty_space.h): voxels per box axis of
  // the occupancy grid built from the maps (once per method and active map
  // set); rays jump over voxels the maps prove empty and take the fine steps
  // only near surfaces, with the same samples there as without it. 0 = off
  // (every step). 64: a voxel spans 4 texels of a 256 px map, so the grid
  // builds in milliseconds and still hugs the object.
  int skip_grid = 64;
  // kRay, depth objects: each map's depth interpolated bilinearly between
  // neighbouring texels inside its silhouette on the same surface (within
  // subtexel_edge texel widths of the nearest texel's depth), instead of the
  // nearest texel's: smooth surfaces instead of one-texel terraces. The
  // silhouettes stay per texel. The slice passes always use nearest texels
  // (their bit-exact CPU reference).
  bool subtexel_depth = false;
  // Depth difference (texel widths) beyond which neighbours count as another
  // surface: 4 keeps slopes up to 76 degrees to the map smooth.
  float subtexel_edge = 4.0f;
  // The most maps a frame tests (0 = every map): of the maps ActiveMaps
  // keeps, the max_maps whose look direction at the box centre is nearest
  // the view's (NearestMaps). Fewer constraints carve less, so the object can
  // only grow; `ibr bench depth-object` measures what it costs. The slice
  // paths count maps in the 8-bit stencil and take at most 255 per frame
  // (robust: 127); larger map sets need the ray path or this subset.
  int max_maps = 0;

  void Check() const;
  // Field by field (tests/ibr/object_kind_registry_test: the CLI and a scene agree).
  bool operator==(const DepthObjectOptions&) const = default;
};

// One map's row of the GPU table (render/passes/depth_object_gpu.h).
using MapRecord = render::DepthMapRecord;

// Every number one frame uses.
struct FrameParams {
  int width = 0, height = 0;  // pixels
  int slice_count = 0;        // slices (kRay: linear-search steps) this frame uses
  bool view_orthographic = false;
  glm::vec4 view_ray{0};  // ax, ay, bx, by (see depth_object_core.glsl)
  float view_height = 0;  // = height, as the float the shader uses
  float inv255 = 1.0f / 255.0f;
  glm::mat4 world_from_box{1}, cam_from_world{1}, clip_from_cam{1};  // for placing slices
  render::SliceStack stack;
  std::vector<glm::vec4> planes;   // per slice: view camera plane dot(xyz, p) = w
  std::vector<MapRecord> maps;     // every map
  std::vector<int> active;         // maps in loop order (the paper's base polygons; FrameMaps)
  int required = 0;                // stencil count a pixel needs (N - k, >= 0)
  bool robust = false;             // robust_k > 0: counting stencil scheme
  float visibility_tolerance = 0;  // scene units
  std::vector<float> weights;      // view-dependent weight per map, over all maps (<= 3 non-zero)
};

// The texel data exactly as uploaded (one layer per map, row 0 = image top).
struct MapTables {
  int layers = 0, width = 0, height = 0;  // max size over maps
  // R32F depth code: -1 outside the silhouette (mask <= 127; visual hulls
  // without a mask: depth <= 0), 0 invalid depth inside it (non-finite and
  // negative values are invalid), else camera z. One fetch per map test.
  std::vector<float> depth;
  std::vector<uint8_t> color;  // RGBA8
  size_t Index(int layer, int col, int row) const {
    return (static_cast<size_t>(layer) * height + row) * width + col;
  }
};

MapTables MakeMapTables(const MapSet& maps, Method method);
// One map's texels of those tables, the one definition of the codes:
// `depth` (and `color`, RGBA8, if not null) for the map's own width x
// height texels, rows `row_stride` texels apart. The renderer uploads each
// map from here, one layer at a time, so no copy of every map is assembled.
void MakeMapLayer(const ImageMap& map, Method method, int row_stride, float* depth, uint8_t* color);

// kAutoSlices: the finest texel of the active maps near the box centre
// (orthographic: 1 / pixels per unit; pinhole: depth of the box centre /
// focal length), in world units, and the count that spaces the slices (kRay:
// the steps) one such texel apart along the box's extent in the slicing
// direction (orthogonal: the chosen box axis; screen, ray: the view's depth
// range over the box), at most 4096.
int AutoSliceCount(const MapSet& maps, const std::vector<int>& active, float extent_world);

FrameParams PrepareFrame(const MapSet& maps, const ViewCamera& view,
                         const DepthObjectOptions& options);

// Owns the GPU resources for one loaded MapSet and renders frames of it: the
// API the command line, the benchmarks and the viewer call per frame.
class DepthObjectRenderer {
 public:
  // Uploads the maps (checked: InputError on bad input). Needs a current context.
  DepthObjectRenderer(render::ProgramCache& programs, MapSet maps);
  ~DepthObjectRenderer();
  DepthObjectRenderer(const DepthObjectRenderer&) = delete;
  DepthObjectRenderer& operator=(const DepthObjectRenderer&) = delete;

  const MapSet& maps() const { return maps_; }
  // Uploads the method's texture arrays now (else the first frame does):
  // each map straight into its layer.
  void Upload(Method method) { Tables(method); }
  // The CPU copy of the method's tables (MakeMapTables), made on first use
  // for the CPU references; rendering never needs it.
  const MapTables& tables(Method method) const;

  // Draws into a frame target of the pass contract (render/passes/pass.h:
  // RGBA8 colour, R32F camera z, R32UI outcome flags, D24S8) already bound
  // and begun: the resolve pass writes gl_FragDepth from `clip_from_cam` and
  // is depth-tested (LESS) against what the frame holds, so objects of
  // several passes composite by depth; empty pixels are left untouched.
  // Restores the GL state it changes. ibr::DepthObjectPass calls it.
  void DrawToFrame(const ViewCamera& view, const DepthObjectOptions& options,
                   const glm::mat4& clip_from_cam, const render::RenderTarget& frame_target);
  // One whole frame of the object alone, read back (the one readback type,
  // render::Frame): BeginFrame on a fresh frame target, the resolve of
  // DrawToFrame without the depth test, render::ReadFrame. Covered pixels: alpha 255, camera z and
  // the hit outcome bit; empty ones 0.
  render::Frame RenderFrame(const ViewCamera& view, const DepthObjectOptions& options);
  // RenderFrame without the readback, into `frame_target` (FrameTargetOptions
  // of the view's size): what the benchmarks time.
  void DrawFrame(const ViewCamera& view, const DepthObjectOptions& options,
                 const render::RenderTarget& frame_target);

  static render::RenderTargetOptions AccumTargetOptions(int width, int height);

  // ---- the stages, exposed for the exactness tests ----
  // Steps 1-2 of sec. 4.1 into `accum` (AccumTargetOptions): attachment 0
  // RGBA32F accumulated w*colour and w, attachment 1 RG32F (z, covered), stencil.
  void DrawSlices(const FrameParams& frame, const DepthObjectOptions& options,
                  const render::RenderTarget& accum);
  // SlicePath::kFast into `accum`, same layout as DrawSlices (the stencil is
  // unused, the depth buffer keeps the front slice): ibr/depth_object_fast.cc.
  void DrawSlicesFast(const FrameParams& frame, const DepthObjectOptions& options,
                      const render::RenderTarget& accum);
  // The ray variant (Slicing::kRay) into `accum`, same layout as DrawSlices.
  void DrawRay(const FrameParams& frame, const DepthObjectOptions& options,
               const render::RenderTarget& accum);
  // Texturing (empty pixels 0) from `accum` into the bound framebuffer; after
  // DrawSlices or DrawRay of the same frame (they upload its map records).
  void DrawResolve(const FrameParams& frame, const DepthObjectOptions& options,
                   const render::RenderTarget& accum);
  // Which pixels each slice polygon covers on this GPU (1 per covered pixel,
  // row 0 on top), for the CPU reference: rasterisation coverage is the one
  // thing the reference takes from the GPU.
  std::vector<core::Image8> SliceCoverage(const FrameParams& frame);

 private:
  struct GpuTables;
  struct SkipTexture;
  const SkipTexture& Skip(const FrameParams& frame, const DepthObjectOptions& options);
  const GpuTables& Tables(Method method);
  std::vector<std::string> Defines(const FrameParams& frame,
                                   const DepthObjectOptions& options) const;
  void BindMaps(const GpuTables& tables) const;
  // Checks that `accum` is the frame's size, uploads the frame's map records
  // and binds the method's map tables: the start of every map pass.
  void BindFrame(const FrameParams& frame, const DepthObjectOptions& options,
                 const render::RenderTarget& accum);
  // Makes `program` current, sets the uniforms every depth-object program
  // reads (and the slicing core's when `slices`); returns its typed uniforms.
  const render::DepthObjectUniforms& SetCommonUniforms(const render::Program& program,
                                                       const FrameParams& frame, bool slices) const;
  const render::RenderTarget& Accum(int width, int height);
  void Accumulate(const FrameParams& frame, const DepthObjectOptions& options);
  // `frame_clip_from_cam`: the pass contract's frame (FRAME_OUTPUT), else
  // the own output layout; `depth_test`: composited by window depth (LESS).
  void Resolve(const FrameParams& frame, const DepthObjectOptions& options,
               const render::RenderTarget& accum, const glm::mat4* frame_clip_from_cam,
               bool depth_test);
  // DrawToFrame, with or without the depth test (RenderFrame: the object alone).
  void DrawIntoFrame(const ViewCamera& view, const DepthObjectOptions& options,
                     const glm::mat4& clip_from_cam, const render::RenderTarget& frame_target,
                     bool depth_test);

  render::ProgramCache* programs_;
  MapSet maps_;
  std::unique_ptr<GpuTables> tables_[2];
  // Skip grids by what they depend on (method, policies, k, active maps, resolution).
  std::map<std::string, std::unique_ptr<SkipTexture>> skip_grids_;
  mutable std::unique_ptr<MapTables> cpu_tables_[2];  // tables(method), on demand
  render::Texture color_maps_;  // RGBA8UI array, one layer per map (both methods)
  // The table buffers, slice buffer and draws (render/passes/depth_object_gpu.h).
  std::unique_ptr<render::DepthObjectGpu> gpu_;
  std::unique_ptr<render::RenderTarget> accum_;
};

// Applies the loop order rule for visual hulls (hull_skip_opposite) and
// returns the maps a frame loops over.
std::vector<int> ActiveMaps(const MapSet& maps, Method method, bool skip_opposite,
                            const glm::dvec3& view_direction);
// Of `active`, the `k` maps whose look direction (orthographic: the axis;
// pinhole: centre to `target`) is nearest `view_direction` (largest cosine;
// ties: lower index), in index order; k <= 0 or k >= active.size(): all.
std::vector<int> NearestMaps(const MapSet& maps, const std::vector<int>& active,
                             const glm::dvec3& view_direction, const glm::dvec3& target, int k);
// The maps a frame from `view_direction` tests: ActiveMaps, then NearestMaps
// with options.max_maps around the box centre.
std::vector<int> FrameMaps(const MapSet& maps, const DepthObjectOptions& options,
                           const glm::dvec3& view_direction);

}  // namespace ibr
