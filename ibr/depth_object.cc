#include "ibr/depth_object.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <glm/gtc/type_ptr.hpp>

#include "core/check.h"
#include "core/error.h"
#include "core/projection.h"
#include "ibr/empty_space.h"
#include "ibr/view_weights.h"
#include "ibr/views.h"
#include "render/cores/ray_core.h"
#include "render/passes/pass.h"

namespace ibr {

// ---- names and options ----

Method MethodFromName(const std::string& name) {
  return core::EnumFromName(kMethodNames, name, "MethodFromName", "method");
}
Slicing SlicingFromName(const std::string& name) {
  return core::EnumFromName(kSlicingNames, name, "SlicingFromName", "slicing");
}
Texturing TexturingFromName(const std::string& name) {
  return core::EnumFromName(kTexturingNames, name, "TexturingFromName", "texturing");
}
int SliceCountFromName(const std::string& name) {
  if (name == "auto") return DepthObjectOptions::kAutoSlices;
  int n = 0;
  size_t used = 0;
  try {
    n = std::stoi(name, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != name.size() || n < 1 || n > 16384) {
    core::ThrowInputError("SliceCountFromName",
                          "slices '{}' is neither 'auto' nor a count in 1..16384", name);
  }
  return n;
}
std::string SliceCountName(int slices) {
  return slices == DepthObjectOptions::kAutoSlices ? "auto" : std::to_string(slices);
}
std::string MethodName(Method m) { return std::string(core::EnumToName(kMethodNames, m)); }
std::string SlicingName(Slicing s) { return std::string(core::EnumToName(kSlicingNames, s)); }
std::string TexturingName(Texturing t) { return std::string(core::EnumToName(kTexturingNames, t)); }

void DepthObjectOptions::Check() const {
  if (slices != kAutoSlices && (slices < 1 || slices > 16384)) {
    core::ThrowInputError("DepthObjectOptions", "slices {} outside 1..16384 (0 = auto)", slices);
  }
  if (robust_k < 0)
    core::ThrowInputError("DepthObjectOptions", "robust k {} is negative", robust_k);
  // The ray core's range: both the ray path and the resolve pass refine with it.
  if (refine_steps < 0 || refine_steps > render::kMaxRayRefineSteps) {
    core::ThrowInputError("DepthObjectOptions", "refine steps {} outside 0..{}", refine_steps,
                          render::kMaxRayRefineSteps);
  }
  if (skip_grid < 0 || skip_grid > 255) {
    core::ThrowInputError("DepthObjectOptions", "skip grid {} outside 0..255", skip_grid);
  }
  if (!(subtexel_edge > 0) || !std::isfinite(subtexel_edge)) {
    core::ThrowInputError("DepthObjectOptions", "subtexel edge {} must be > 0 texels",
                          subtexel_edge);
  }
  if (!(visibility_tolerance >= 0) || !std::isfinite(visibility_tolerance)) {
    core::ThrowInputError("DepthObjectOptions", "visibility tolerance {} must be >= 0",
                          visibility_tolerance);
  }
  if (max_maps < 0 || max_maps > kMaxMaps) {
    core::ThrowInputError("DepthObjectOptions", "max maps {} outside 0..{} (0 = all)", max_maps,
                          kMaxMaps);
  }
}

// ---- CPU preparation ----

void MakeMapLayer(const ImageMap& m, Method method, int row_stride, float* depth, uint8_t* color) {
  IBR_CHECK_GE(row_stride, m.camera.width);
  for (int row = 0; row < m.camera.height; ++row) {
    for (int col = 0; col < m.camera.width; ++col) {
      const size_t i = static_cast<size_t>(row) * row_stride + col;
      float d = m.depth.empty() ? 0.0f : m.depth.at(col, row);
      if (!std::isfinite(d) || d < 0) d = 0;
      bool inside;
      if (!m.mask.empty()) {
        inside = m.mask.at(col, row) > 127;
      } else if (method == Method::kVisualHull) {
        inside = d > 0;  // silhouette from valid depth
      } else {
        inside = true;  // no silhouette: depth alone decides
      }
      depth[i] = inside ? d : -1.0f;
      if (color == nullptr) continue;
      uint8_t* c = color + i * 4;
      if (m.color.empty()) {
        c[0] = c[1] = c[2] = c[3] = 255;
      } else {
        for (int k = 0; k < 3; ++k) c[k] = m.color.at(col, row, k);
        c[3] = m.color.channels() == 4 ? m.color.at(col, row, 3) : 255;
      }
    }
  }
}

MapTables MakeMapTables(const MapSet& maps, Method method) {
  MapTables t;
  t.layers = static_cast<int>(maps.maps.size());
  for (const ImageMap& m : maps.maps) {
    t.width = std::max(t.width, m.camera.width);
    t.height = std::max(t.height, m.camera.height);
  }
  const size_t n = static_cast<size_t>(t.layers) * t.width * t.height;
  t.depth.assign(n, -1.0f);
  t.color.assign(n * 4, 255);
  for (int l = 0; l < t.layers; ++l) {
    MakeMapLayer(maps.maps[l], method, t.width, &t.depth[t.Index(l, 0, 0)],
                 &t.color[t.Index(l, 0, 0) * 4]);
  }
  return t;
}

namespace {

glm::dvec3 BoxCentre(const MapSet& maps) {
  return glm::dvec3(maps.world_from_box * glm::dvec4(0.5, 0.5, 0.5, 1.0));
}

// The direction a camera looks at the box: orthographic: its axis; pinhole:
// from its centre to the box centre (its axis if it sits at the centre).
glm::dvec3 LookDirection(bool orthographic, const glm::dmat4& cam_from_world,
                         const glm::dvec3& target) {
  const glm::dvec3 axis = CameraAxis(cam_from_world);
  if (orthographic) return axis;
  const glm::dvec3 d = target - CameraCentre(cam_from_world);
  const double len = glm::length(d);
  return len > 1e-12 ? d / len : axis;
}

}  // namespace

std::vector<int> ActiveMaps(const MapSet& maps, Method method, bool skip_opposite,
                            const glm::dvec3& view_direction) {
  const int n = static_cast<int>(maps.maps.size());
  std::vector<int> active;
  for (int i = 0; i < n; ++i) {
    bool skip = false;
    const ImageMap& a = maps.maps[i];
    if (method == Method::kVisualHull && skip_opposite && a.camera.orthographic) {
      const glm::dvec3 ai = CameraAxis(a.cam_from_world);
      for (int j = 0; j < n && !skip; ++j) {
        const ImageMap& b = maps.maps[j];
        if (j == i || !b.camera.orthographic) continue;
        const glm::dvec3 aj = CameraAxis(b.cam_from_world);
        if (glm::dot(ai, aj) > -1.0 + 1e-9) continue;
        // Opposite pair: keep the one looking along the view (its face is the
        // one the viewer sees); exact ties keep the lower index.
        const double si = glm::dot(ai, view_direction), sj = glm::dot(aj, view_direction);
        if (sj > si || (sj == si && j < i)) skip = true;
      }
    }
    if (!skip) active.push_back(i);
  }
  return active;
}

std::vector<int> NearestMaps(const MapSet& maps, const std::vector<int>& active,
                             const glm::dvec3& view_direction, const glm::dvec3& target, int k) {
  if (k <= 0 || k >= static_cast<int>(active.size())) return active;
  std::vector<std::pair<double, int>> by_cosine;
  for (int i : active) {
    const ImageMap& m = maps.maps[i];
    const glm::dvec3 d = LookDirection(m.camera.orthographic, m.cam_from_world, target);
    by_cosine.emplace_back(-glm::dot(d, view_direction), i);
  }
  std::sort(by_cosine.begin(), by_cosine.end());  // largest cosine first, ties by index
  std::vector<int> nearest;
  for (int j = 0; j < k; ++j) nearest.push_back(by_cosine[j].second);
  std::sort(nearest.begin(), nearest.end());
  return nearest;
}

std::vector<int> FrameMaps(const MapSet& maps, const DepthObjectOptions& options,
                           const glm::dvec3& view_direction) {
  return NearestMaps(maps,
                     ActiveMaps(maps, options.method, options.hull_skip_opposite, view_direction),
                     view_direction, BoxCentre(maps), options.max_maps);
}

int AutoSliceCount(const MapSet& maps, const std::vector<int>& active, float extent_world) {
  const glm::dvec3 centre = BoxCentre(maps);
  double texel = INFINITY;
  for (int i : active) {
    const ImageMap& m = maps.maps[i];
    const double f = std::max(m.camera.fx, m.camera.fy);
    if (m.camera.orthographic) {
      texel = std::min(texel, 1.0 / f);
    } else {
      const double z = (m.cam_from_world * glm::dvec4(centre, 1.0)).z;
      if (z > 0) texel = std::min(texel, z / f);
    }
  }
  if (!std::isfinite(texel) || !(texel > 0))
    return 256;  // no map sees the box centre: the paper's range
  const double n = std::ceil(extent_world / texel);
  return static_cast<int>(std::clamp(n, 1.0, 4096.0));
}

FrameParams PrepareFrame(const MapSet& maps, const ViewCamera& view,
                         const DepthObjectOptions& options) {
  options.Check();
  view.camera.Check("PrepareFrame: view");
  FrameParams f;
  const MapCamera& vc = view.camera;
  f.width = vc.width;
  f.height = vc.height;
  f.view_orthographic = vc.orthographic;
  f.view_height = static_cast<float>(vc.height);
  f.view_ray = glm::vec4(1.0 / vc.fx, 1.0 / vc.fy, -vc.cx / vc.fx, -vc.cy / vc.fy);

  // Near/far only clip the slice polygons (no depth test is used): generous.
  const glm::dmat4 cam_from_box = view.cam_from_world * maps.world_from_box;
  double zmin = INFINITY, zmax = -INFINITY;
  for (int i = 0; i < 8; ++i) {
    const glm::dvec3 p(cam_from_box * glm::dvec4(i & 1, (i >> 1) & 1, (i >> 2) & 1, 1.0));
    zmin = std::min(zmin, p.z);
    zmax = std::max(zmax, p.z);
  }
  const double extent = std::max(zmax - zmin, 1e-9);
  if (vc.orthographic) {
    f.clip_from_cam = core::ClipFromCamOrthographic(vc.fx, vc.fy, vc.cx, vc.cy, vc.width, vc.height,
                                                    zmin - 0.5 * extent, zmax + 0.5 * extent);
  } else {
    const double far = std::max(zmax, 0.0) + extent;
    const double near = std::max(zmin * 0.5, far * 1e-5);
    f.clip_from_cam =
        core::ClipFromCamPerspective(vc.fx, vc.fy, vc.cx, vc.cy, vc.width, vc.height, near, far);
  }
  f.world_from_box = glm::mat4(maps.world_from_box);
  f.cam_from_world = glm::mat4(view.cam_from_world);

  // Slices from the shared slicing core, front to back (sec. 4.1: "we slice
  // the cube from front to back in the best orthogonal direction").
  render::SlicingOptions so;
  // (kRay uses the screen stack only for its spacing: its step along camera z.)
  so.family = options.slicing == Slicing::kOrthogonal ? render::SliceFamily::kOrthogonal
                                                      : render::SliceFamily::kScreen;
  so.order = render::SliceOrder::kFrontToBack;
  so.count = options.slices;
  if (options.slices == DepthObjectOptions::kAutoSlices) {
    // The slicing direction's extent over the box: the orthogonal family's
    // axis (the distance between its planes x_axis = 0 and 1), else the
    // view's depth range.
    so.count = 1;
    const render::SliceStack one =
        render::MakeSlices({f.world_from_box}, {f.cam_from_world, vc.orthographic}, so);
    const float extent_along = one.spacing_world;
    const std::vector<int> active = FrameMaps(
        maps, options, LookDirection(vc.orthographic, view.cam_from_world, BoxCentre(maps)));
    so.count = AutoSliceCount(maps, active, extent_along);
  }
  f.slice_count = so.count;
  f.stack = render::MakeSlices({f.world_from_box}, {f.cam_from_world, vc.orthographic}, so);
  // Each slice plane in view camera space: p_box = A p_cam + b, so
  // dot(n_box, p_box) = c  <=>  dot(A^T n_box, p_cam) = c - dot(n_box, b).
  const glm::dmat4 box_from_cam = glm::inverse(cam_from_box);
  const glm::dmat3 a(box_from_cam);
  const glm::dvec3 b(box_from_cam[3]);
  const glm::dvec3 n_box(f.stack.normal_in_box);
  for (const render::Slice& s : f.stack.slices) {
    const glm::dvec3 n_cam = glm::transpose(a) * n_box;
    f.planes.emplace_back(glm::vec3(n_cam),
                          static_cast<float>(s.offset_in_box - glm::dot(n_box, b)));
  }

  // Maps: view camera -> map camera, projection, texture layer.
  const glm::dvec3 centre = BoxCentre(maps);
  const glm::dvec3 view_dir = LookDirection(vc.orthographic, view.cam_from_world, centre);
  const glm::dmat4 world_from_view = glm::inverse(view.cam_from_world);
  const glm::dmat3 view_from_world_r(view.cam_from_world);
  for (size_t i = 0; i < maps.maps.size(); ++i) {
    const ImageMap& m = maps.maps[i];
    const glm::dmat4 mv = m.cam_from_world * world_from_view;
    MapRecord r{};
    r.m0 = glm::vec4(glm::vec3(mv[0]), 0);
    r.m1 = glm::vec4(glm::vec3(mv[1]), 0);
    r.m2 = glm::vec4(glm::vec3(mv[2]), 0);
    r.m3 = glm::vec4(glm::vec3(mv[3]), 0);
    r.proj = glm::vec4(m.camera.fx, m.camera.fy, m.camera.cx, m.camera.cy);
    r.info = glm::ivec4(m.camera.width, m.camera.height, m.camera.orthographic ? 1 : 0,
                        static_cast<int>(i));
    const glm::dvec3 c_view(view.cam_from_world * glm::dvec4(CameraCentre(m.cam_from_world), 1.0));
    r.centre_in_view = glm::vec4(glm::vec3(c_view), m.camera.orthographic ? 1.0f : 0.0f);
    r.axis_in_view = glm::vec4(glm::vec3(view_from_world_r * CameraAxis(m.cam_from_world)), 0.0f);
    f.maps.push_back(r);
  }
  f.active = FrameMaps(maps, options, view_dir);
  const int n = static_cast<int>(f.active.size());
  f.robust = options.robust_k > 0;
  f.required = std::max(n - options.robust_k, 0);

  // View-dependent weights over every map (sec. 4.2, ibr/view_weights.h), not
  // only the active ones: a hull's active set swaps a map for its opposite
  // where the view crosses a face plane, and weights over the three active
  // maps alone then jumped there (the swapped map still held a visible share
  // of the weight); over all maps
  // the swapping pair both sit at the 4th-smallest angle, weight 0. The map
  // loop blends the active maps' share (the resolve divides by its sum).
  std::vector<glm::dvec3> dirs;
  for (const ImageMap& m : maps.maps) {
    dirs.push_back(LookDirection(m.camera.orthographic, m.cam_from_world, centre));
  }
  f.weights = ViewDependentWeights(dirs, view_dir, 3);
  for (size_t i = 0; i < f.maps.size(); ++i) f.maps[i].extra.x = f.weights[i];
  // The shaders' list of the active maps (the uniform block's; the storage
  // buffer path uploads `active` itself).
  for (int j = 0; j < n; ++j) f.maps[j].extra.y = static_cast<float>(f.active[j]);
  f.visibility_tolerance =
      static_cast<float>(options.visibility_tolerance > 0 ? options.visibility_tolerance
                                                          : 4.0 * f.stack.spacing_world);
  return f;
}

// ---- GPU ----

struct DepthObjectRenderer::GpuTables {
  render::Texture depth;  // R32F depth codes, one layer per map (the colour is shared: color_maps_)
};

struct DepthObjectRenderer::SkipTexture {
  int resolution = 0;
  render::Texture grid;  // R8UI 3D, ibr::SkipGrid::distance
};

namespace {

// Where the maps came from, for error messages.
std::string MapsWhere(const MapSet& maps) {
  return maps.source.empty() ? std::string("DepthObjectRenderer")
                             : fmt::format("DepthObjectRenderer: '{}'", maps.source);
}

// The largest map's size: every layer of the map arrays has it.
glm::ivec2 MaxMapSize(const MapSet& maps) {
  glm::ivec2 size(0);
  for (const ImageMap& m : maps.maps) size = glm::max(size, {m.camera.width, m.camera.height});
  return size;
}

}  // namespace

DepthObjectRenderer::DepthObjectRenderer(render::ProgramCache& programs, MapSet maps)
    : programs_(&programs), maps_(std::move(maps)) {
  maps_.Check(MapsWhere(maps_));
  const glm::ivec2 size = MaxMapSize(maps_);
  gpu_ = std::make_unique<render::DepthObjectGpu>(static_cast<int>(maps_.maps.size()), size.x,
                                                  size.y, MapsWhere(maps_));
}

DepthObjectRenderer::~DepthObjectRenderer() = default;

const DepthObjectRenderer::GpuTables& DepthObjectRenderer::Tables(Method method) {
  auto& slot = tables_[method == Method::kDepthObject ? 0 : 1];
  if (!slot) {
    // Each map straight into its layer (no copy of every map is assembled):
    // its depth codes through one layer of staging, its colour from the
    // image itself when it is RGBA, else through staging too. Texels beyond
    // a smaller map's size are never read (MapLookup tests its own size).
    const glm::ivec2 size = MaxMapSize(maps_);
    const int layers = static_cast<int>(maps_.maps.size());
    const bool upload_color = color_maps_.id() == 0;
    slot = std::make_unique<GpuTables>();
    slot->depth = gpu_->CreateMapArray(GL_R32F, 4);
    if (upload_color) color_maps_ = gpu_->CreateMapArray(GL_RGBA8UI, 4);
    std::vector<float> depth(static_cast<size_t>(size.x) * size.y);
    std::vector<uint8_t> color;
    for (int l = 0; l < layers; ++l) {
      const ImageMap& m = maps_.maps[l];
      const int mw = m.camera.width, mh = m.camera.height;
      const bool rgba = !m.color.empty() && m.color.channels() == 4;
      if (upload_color && !rgba) color.resize(static_cast<size_t>(mw) * mh * 4);
      MakeMapLayer(m, method, mw, depth.data(), upload_color && !rgba ? color.data() : nullptr);
      render::DepthObjectGpu::UploadLayer(slot->depth, l, mw, mh, GL_RED, GL_FLOAT, depth.data());
      if (upload_color) {
        render::DepthObjectGpu::UploadLayer(color_maps_, l, mw, mh, GL_RGBA_INTEGER,
                                            GL_UNSIGNED_BYTE, rgba ? m.color.data() : color.data());
      }
    }
  }
  return *slot;
}

const DepthObjectRenderer::SkipTexture& DepthObjectRenderer::Skip(
    const FrameParams& frame, const DepthObjectOptions& options) {
  SkipGridPolicy policy;
  policy.visual_hull = options.method == Method::kVisualHull;
  policy.outside_passes = options.outside == OutsidePolicy::kPass;
  policy.invalid_depth_passes = options.invalid_depth == InvalidDepthPolicy::kNoConstraint;
  policy.rejections_needed = static_cast<int>(frame.active.size()) - frame.required + 1;
  std::string key = fmt::format("{} {} {} {} {} {}:", policy.visual_hull, policy.outside_passes,
                                policy.invalid_depth_passes, policy.rejections_needed,
                                options.skip_grid, frame.active.size());
  for (int a : frame.active) key += fmt::format(" {}", a);
  auto& slot = skip_grids_[key];
  if (!slot) {
    // Each active map's depth codes, one map at a time (MakeMapLayer: the
    // texels the GPU reads).
    const Method method = options.method;
    const SkipGrid grid = BuildSkipGrid(
        maps_,
        [&](int map_index, std::vector<float>& codes) {
          const ImageMap& m = maps_.maps[map_index];
          codes.resize(static_cast<size_t>(m.camera.width) * m.camera.height);
          MakeMapLayer(m, method, m.camera.width, codes.data(), nullptr);
        },
        frame.active, policy, options.skip_grid);
    slot = std::make_unique<SkipTexture>();
    const int n = grid.resolution;
    slot->resolution = n;
    slot->grid = render::Texture::Create3DWithData(GL_R8UI, {n, n, n}, GL_RED_INTEGER,
                                                   GL_UNSIGNED_BYTE, grid.distance.data());
  }
  return *slot;
}

const MapTables& DepthObjectRenderer::tables(Method method) const {
  auto& slot = cpu_tables_[method == Method::kDepthObject ? 0 : 1];
  if (!slot) slot = std::make_unique<MapTables>(MakeMapTables(maps_, method));
  return *slot;
}

render::RenderTargetOptions DepthObjectRenderer::AccumTargetOptions(int width, int height) {
  return {width, height, {GL_RGBA32F, GL_RG32F}, true};
}

const render::RenderTarget& DepthObjectRenderer::Accum(int width, int height) {
  if (!accum_ || accum_->width() != width || accum_->height() != height) {
    accum_ = std::make_unique<render::RenderTarget>(AccumTargetOptions(width, height));
  }
  return *accum_;
}

std::vector<std::string> DepthObjectRenderer::Defines(const FrameParams& frame,
                                                      const DepthObjectOptions& options) const {
  std::vector<std::string> d;
  const int uniform_maps = gpu_->uniform_maps();
  d.push_back(uniform_maps > 0 ? fmt::format("MAX_MAPS {}", uniform_maps)
                               : std::string("MAPS_IN_STORAGE_BUFFER"));
  if (options.method == Method::kVisualHull) d.push_back("VISUAL_HULL");
  if (options.outside == OutsidePolicy::kPass) d.push_back("OUTSIDE_PASSES");
  if (options.invalid_depth == InvalidDepthPolicy::kNoConstraint)
    d.push_back("INVALID_DEPTH_PASSES");
  if (frame.view_orthographic) d.push_back("VIEW_ORTHOGRAPHIC");
  return d;
}

void DepthObjectRenderer::BindMaps(const GpuTables& t) const {
  gpu_->BindMaps(t.depth, color_maps_);
}

const render::DepthObjectUniforms& DepthObjectRenderer::SetCommonUniforms(const render::Program& p,
                                                                          const FrameParams& frame,
                                                                          bool slices) const {
  p.Use();
  const auto& u = p.Typed<render::DepthObjectUniforms>();
  u.depth_maps.Set(0);
  u.color_maps.Set(2);
  u.map_count.Set(static_cast<int>(frame.maps.size()));
  u.active_count.Set(static_cast<int>(frame.active.size()));
  u.view_ray.Set(frame.view_ray);
  u.view_height.Set(frame.view_height);
  u.inv255.Set(frame.inv255);
  if (slices) {
    u.world_from_box.Set(glm::mat4(frame.world_from_box));
    u.cam_from_world.Set(glm::mat4(frame.cam_from_world));
    u.clip_from_cam.Set(glm::mat4(frame.clip_from_cam));
  }
  return u;
}

void DepthObjectRenderer::BindFrame(const FrameParams& frame, const DepthObjectOptions& options,
                                    const render::RenderTarget& accum) {
  IBR_CHECK_EQ(accum.width(), frame.width);
  IBR_CHECK_EQ(accum.height(), frame.height);
  gpu_->UploadFrame(frame.maps, frame.active);
  BindMaps(Tables(options.method));
}

void DepthObjectRenderer::DrawSlices(const FrameParams& frame, const DepthObjectOptions& options,
                                     const render::RenderTarget& accum) {
  // The paper's scheme counts the maps a pixel passed in the 8-bit stencil
  // (robust: its low 7 bits).
  const size_t stencil_maps = frame.robust ? 127 : 255;
  if (frame.active.size() > stencil_maps) {
    core::ThrowInputError(MapsWhere(maps_),
                          "{} maps in one frame; the slice paths count them in the 8-bit stencil, "
                          "at most {}{}: use the ray path (--slicing ray) or a subset (--max-maps)",
                          frame.active.size(), stencil_maps, frame.robust ? " with --robust" : "");
  }
  BindFrame(frame, options, accum);
  const render::Program& pass = programs_->Get({.vertex = "cores/slice.vert.glsl",
                                                .fragment = "passes/depth_object.frag.glsl",
                                                .defines = Defines(frame, options)});
  const render::DepthObjectUniforms& u = SetCommonUniforms(pass, frame, true);
  gpu_->DrawStencilSlices(frame.stack,
                          {.planes = frame.planes,
                           .active = frame.active,
                           .required = frame.required,
                           .robust = frame.robust},
                          u, accum);
}

void DepthObjectRenderer::DrawRay(const FrameParams& frame, const DepthObjectOptions& options,
                                  const render::RenderTarget& accum) {
  BindFrame(frame, options, accum);
  render::RayCoreOptions ray;
  ray.max_steps = frame.slice_count + 2;  // the box's depth range in slice spacings, plus the ends
  ray.refine_steps = options.refine_steps;
  std::vector<std::string> defines = Defines(frame, options);
  if (frame.robust) defines.push_back("ROBUST_COUNT");
  const SkipTexture* skip = options.skip_grid > 0 ? &Skip(frame, options) : nullptr;
  if (skip) defines.push_back("EMPTY_SPACE_SKIPPING");
  if (options.subtexel_depth) defines.push_back("SUBTEXEL_DEPTH");
  for (const std::string& d : render::RayCoreDefines(ray)) defines.push_back(d);
  const render::Program& program = programs_->Get({.vertex = "common/fullscreen.vert.glsl",
                                                   .fragment = "passes/depth_object_ray.frag.glsl",
                                                   .defines = defines});
  const render::DepthObjectUniforms& u = SetCommonUniforms(program, frame, false);
  render::SetRayCoreUniforms(program, ray);
  const glm::mat4 box_from_cam = glm::inverse(frame.cam_from_world * frame.world_from_box);
  u.box_from_cam.Set(glm::mat4(box_from_cam));
  u.required.Set(frame.required);
  u.ray_step.Set(frame.stack.spacing_world);
  if (options.subtexel_depth) u.subtexel_edge.Set(options.subtexel_edge);
  if (skip) {
    render::DepthObjectGpu::BindTexture(5, skip->grid);
    u.skip_grid.Set(5);
    u.skip_resolution.Set(skip->resolution);
  }
  accum.Bind();
  gpu_->DrawFullScreen(/*depth_test=*/false);
}

void DepthObjectRenderer::DrawResolve(const FrameParams& frame, const DepthObjectOptions& options,
                                      const render::RenderTarget& accum) {
  Resolve(frame, options, accum, nullptr, /*depth_test=*/false);
}

void DepthObjectRenderer::Resolve(const FrameParams& frame, const DepthObjectOptions& options,
                                  const render::RenderTarget& accum,
                                  const glm::mat4* frame_clip_from_cam, bool depth_test) {
  // After DrawSlices / DrawRay of this frame: their BindFrame uploaded its map
  // records, so only the tables are bound again.
  IBR_CHECK_EQ(accum.width(), frame.width);
  IBR_CHECK_EQ(accum.height(), frame.height);
  BindMaps(Tables(options.method));
  std::vector<std::string> defines = Defines(frame, options);
  defines.push_back(options.texturing == Texturing::kViewDependent ? "TEXTURING_VDT"
                    : options.texturing == Texturing::kVisibility  ? "TEXTURING_VISIBILITY"
                    : options.texturing == Texturing::kPaperBlend  ? "TEXTURING_VDT_PAPER"
                                                                   : "TEXTURING_NONE");
  if (frame.robust) defines.push_back("ROBUST_COUNT");
  // The ray variant's hits are already refined by the ray core; the slice
  // passes' are refined here by the same refinement (render/cores/ray_core.h).
  const bool refine =
      options.refine_steps > 0 && frame.planes.size() >= 2 && options.slicing != Slicing::kRay;
  render::RayCoreOptions ray;
  ray.refine_steps = options.refine_steps;
  for (const std::string& d : render::RayCoreDefines(ray)) defines.push_back(d);
  if (frame_clip_from_cam) defines.push_back("FRAME_OUTPUT");
  const render::Program& resolve =
      programs_->Get({.vertex = "common/fullscreen.vert.glsl",
                      .fragment = "passes/depth_object_resolve.frag.glsl",
                      .defines = defines});
  const render::DepthObjectUniforms& u = SetCommonUniforms(resolve, frame, false);
  render::DepthObjectGpu::BindTexture(3, accum.color(0));
  render::DepthObjectGpu::BindTexture(4, accum.color(1));
  u.accum_color.Set(3);
  u.accum_depth.Set(4);
  u.visibility_tolerance.Set(frame.visibility_tolerance);
  render::SetRayCoreUniforms(resolve, ray);
  u.refine.Set(refine ? 1 : 0);
  if (refine) {
    u.plane0.Set(frame.planes[0]);
    // Box-axis planes are 1/n apart in box units; screen planes spacing_world
    // apart in camera z (their normals are those units' gradients).
    u.plane_step.Set(frame.stack.axis >= 0 ? frame.stack.spacing_in_box
                                           : frame.stack.spacing_world);
  }
  u.required.Set(frame.required);
  if (frame_clip_from_cam) u.clip_from_cam.Set(glm::mat4(*frame_clip_from_cam));
  gpu_->DrawFullScreen(depth_test);
}

void DepthObjectRenderer::Accumulate(const FrameParams& frame, const DepthObjectOptions& options) {
  const render::RenderTarget& accum = Accum(frame.width, frame.height);
  if (options.slicing == Slicing::kRay) {
    DrawRay(frame, options, accum);
  } else if (options.slice_path == SlicePath::kFast) {
    DrawSlicesFast(frame, options, accum);
  } else {
    DrawSlices(frame, options, accum);
  }
}

void DepthObjectRenderer::DrawToFrame(const ViewCamera& view, const DepthObjectOptions& options,
                                      const glm::mat4& clip_from_cam,
                                      const render::RenderTarget& frame_target) {
  DrawIntoFrame(view, options, clip_from_cam, frame_target, /*depth_test=*/true);
}

void DepthObjectRenderer::DrawIntoFrame(const ViewCamera& view, const DepthObjectOptions& options,
                                        const glm::mat4& clip_from_cam,
                                        const render::RenderTarget& frame_target, bool depth_test) {
  if (frame_target.width() != view.camera.width || frame_target.height() != view.camera.height) {
    core::ThrowInputError("DepthObjectRenderer::DrawToFrame",
                          "target {}x{} differs from the view's {}x{}", frame_target.width(),
                          frame_target.height(), view.camera.width, view.camera.height);
  }
  const render::SavedDepthState saved;
  const FrameParams frame = PrepareFrame(maps_, view, options);
  Accumulate(frame, options);
  frame_target.Bind();
  render::BindOutcomeImage(frame_target, 0);
  Resolve(frame, options, Accum(frame.width, frame.height), &clip_from_cam, depth_test);
}

render::Frame DepthObjectRenderer::RenderFrame(const ViewCamera& view,
                                               const DepthObjectOptions& options) {
  const render::RenderTarget target(
      render::FrameTargetOptions(view.camera.width, view.camera.height));
  DrawFrame(view, options, target);
  return render::ReadFrame(target);
}

void DepthObjectRenderer::DrawFrame(const ViewCamera& view, const DepthObjectOptions& options,
                                    const render::RenderTarget& frame_target) {
  render::BeginFrame(frame_target);
  // The object alone: no depth test, so every covered pixel lands whatever
  // the window depth (the clip range only fills the depth buffer).
  DrawIntoFrame(view, options, ViewSetupFor(view, BoxBounds(maps_.world_from_box)).clip_from_cam,
                frame_target, /*depth_test=*/false);
}

std::vector<core::Image8> DepthObjectRenderer::SliceCoverage(const FrameParams& frame) {
  // The clear pass writes constants and never discards.
  DepthObjectOptions o;
  const render::Program& p = programs_->Get({.vertex = "cores/slice.vert.glsl",
                                             .fragment = "passes/depth_object.frag.glsl",
                                             .defines = Defines(frame, o)});
  SetCommonUniforms(p, frame, true).clear_pass.Set(1);
  return gpu_->SliceCoverage(frame.stack, frame.width, frame.height);
}

}  // namespace ibr
