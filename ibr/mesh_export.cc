#include "ibr/mesh_export.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>

#include "core/check.h"
#include "core/error.h"
#include "core/memory_budget.h"
#include "core/mesh_compare.h"
#include "core/mesh_write.h"
#include "ibr/dataset_maps.h"
#include "ibr/view_weights.h"

namespace ibr {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// One map as the field reads it: its pose, camera and the renderer's texel
// codes (MakeMapLayer: < 0 outside the silhouette, 0 invalid, > 0 camera z).
struct FieldMap {
  const ImageMap* map = nullptr;
  glm::dmat4 cam_from_world{1.0}, world_from_cam{1.0};
  std::vector<float> codes;
  std::vector<uint8_t> rgba;
  float Code(int col, int row) const {
    return codes[static_cast<size_t>(row) * map->camera.width + col];
  }
};

// Where a world point falls in a map (the shader's MapLookupUv, in double).
struct Lookup {
  glm::dvec3 q{0.0};  // map camera point
  double u = 0, v = 0;
  bool inside = false;  // in front of the map and inside its image
};

Lookup Project(const FieldMap& m, const glm::dvec3& p) {
  Lookup l;
  l.q = glm::dvec3(m.cam_from_world * glm::dvec4(p, 1.0));
  const MapCamera& c = m.map->camera;
  l.inside = c.Project(l.q, l.u, l.v) && c.InImage(l.u, l.v);
  return l;
}

double TexelSize(const MapCamera& c, double q_z) {
  return c.orthographic ? 1.0 / c.fx : q_z / c.fx;
}

// The bilinear 2x2 footprint around image point (u, v) (texel centres at +0.5).
struct Footprint {
  int col[4], row[4];
  double weight[4];
};
Footprint FootprintAt(const MapCamera& c, double u, double v) {
  Footprint f;
  const double fu = u - 0.5, fv = v - 0.5;
  const int i0 = static_cast<int>(std::floor(fu)), j0 = static_cast<int>(std::floor(fv));
  const double tx = fu - i0, ty = fv - j0;
  for (int k = 0; k < 4; ++k) {
    f.col[k] = std::clamp(i0 + (k & 1), 0, c.width - 1);
    f.row[k] = std::clamp(j0 + (k >> 1), 0, c.height - 1);
    f.weight[k] = ((k & 1) ? tx : 1 - tx) * ((k >> 1) ? ty : 1 - ty);
  }
  return f;
}

// The renderer's object field in double precision (depth_object_core.glsl:
// MapField, SubtexelDepth, ObjectField), clamped to [-band, band].
class ObjectField {
 public:
  ObjectField(const MapSet& maps, const MeshExportOptions& options, OutsidePolicy outside,
              double band)
      : options_(options), outside_free_(outside == OutsidePolicy::kPass), band_(band) {
    box_from_world_ = glm::inverse(maps.world_from_box);
    for (const ImageMap& m : maps.maps) {
      FieldMap f;
      f.map = &m;
      f.cam_from_world = m.cam_from_world;
      f.world_from_cam = glm::inverse(m.cam_from_world);
      const size_t n = static_cast<size_t>(m.camera.width) * m.camera.height;
      f.codes.resize(n);
      f.rgba.resize(4 * n);
      MakeMapLayer(m, options.method, m.camera.width, f.codes.data(), f.rgba.data());
      maps_.push_back(std::move(f));
    }
  }

  const std::vector<FieldMap>& maps() const { return maps_; }
  double band() const { return band_; }

  // Map m's signed value at p: <= 0 where it accepts p (scene units), +-inf
  // where it carves / does not constrain.
  double MapValue(const FieldMap& m, const glm::dvec3& p) const {
    const Lookup l = Project(m, p);
    if (!l.inside) return outside_free_ ? -kInf : kInf;
    const float code = m.Code(static_cast<int>(l.u), static_cast<int>(l.v));
    if (code < 0) return kInf;
    if (options_.method == Method::kVisualHull) return -kInf;
    if (code == 0)
      return options_.invalid_depth == InvalidDepthPolicy::kNoConstraint ? -kInf : kInf;
    return Depth(m, l, code) - l.q.z;
  }

  // <= 0 inside the object.
  double operator()(const glm::dvec3& p) const {
    const glm::dvec3 b(box_from_world_ * glm::dvec4(p, 1.0));
    if (b.x < 0 || b.y < 0 || b.z < 0 || b.x > 1 || b.y > 1 || b.z > 1) return band_;
    if (options_.robust_k == 0) {
      double f = -kInf;
      for (const FieldMap& m : maps_) {
        f = std::max(f, MapValue(m, p));
        if (f >= band_) return band_;
      }
      return std::clamp(f, -band_, band_);
    }
    // Robust (ObjectField's ROBUST_COUNT): inside when at least N - K maps
    // accept, i.e. the (K + 1)-th largest map value is <= 0; that value is
    // the field, so the surface stays interpolable.
    const int k = options_.robust_k;
    if (k >= static_cast<int>(maps_.size())) return -band_;
    thread_local std::vector<double> values;
    values.clear();
    for (const FieldMap& m : maps_) values.push_back(MapValue(m, p));
    std::nth_element(values.begin(), values.begin() + k, values.end(), std::greater<>());
    return std::clamp(values[k], -band_, band_);
  }

 private:
  // SubtexelDepth: bilinear over the 2x2 texels on the same surface as the
  // nearest (within subtexel_edge texel widths), else the nearest texel's.
  double Depth(const FieldMap& m, const Lookup& l, float d0) const {
    if (!options_.subtexel_depth) return d0;
    const MapCamera& c = m.map->camera;
    const Footprint f = FootprintAt(c, l.u, l.v);
    const double edge = options_.subtexel_edge * TexelSize(c, l.q.z);
    double wsum = 0, dsum = 0;
    for (int k = 0; k < 4; ++k) {
      const float dk = m.Code(f.col[k], f.row[k]);
      if (dk > 0 && std::abs(static_cast<double>(dk) - d0) <= edge) {
        wsum += f.weight[k];
        dsum += f.weight[k] * dk;
      }
    }
    return wsum > 0 ? dsum / wsum : d0;
  }

  MeshExportOptions options_;
  bool outside_free_;
  double band_;
  glm::dmat4 box_from_world_{1.0};
  std::vector<FieldMap> maps_;
};

void CheckMapsFor(const MapSet& maps, Method method) {
  const std::string where = "ibr export: '" + maps.source + "'";
  for (const ImageMap& m : maps.maps) {
    if (method == Method::kDepthObject && m.depth.empty()) {
      core::ThrowInputError(where,
                            "view '{}' has no depth map (a depth object needs depth in every "
                            "view; --method visual-hull uses the masks)",
                            m.name);
    }
    if (method == Method::kVisualHull && m.mask.empty() && m.depth.empty()) {
      core::ThrowInputError(where,
                            "view '{}' has neither a mask nor depth (a visual hull needs "
                            "a silhouette in every view)",
                            m.name);
    }
  }
}

struct Grid {
  glm::dvec3 origin{0.0};  // world position of sample (0, 0, 0)
  double h = 0;            // voxel size
  glm::ivec3 dims{0};
  size_t count() const { return static_cast<size_t>(dims.x) * dims.y * dims.z; }
};

Grid MakeGrid(const MapSet& maps, double voxel) {
  glm::dvec3 lo(kInf), hi(-kInf);
  for (int c = 0; c < 8; ++c) {
    const glm::dvec3 p(maps.world_from_box * glm::dvec4(c & 1, (c >> 1) & 1, (c >> 2) & 1, 1.0));
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  Grid g;
  g.h = voxel;
  // One sample outside the box on every side, so the surface closes where
  // the object meets the box.
  for (int a = 0; a < 3; ++a) {
    const int cells = static_cast<int>(std::ceil((hi[a] - lo[a]) / voxel));
    g.dims[a] = cells + 3;
    g.dims[a] += 1 - g.dims[a] % 2;  // odd: the even samples (FillField's coarse pass) span it
    g.origin[a] = 0.5 * (lo[a] + hi[a]) - 0.5 * (g.dims[a] - 1) * voxel;
  }
  return g;
}

double VoxelOf(const MapSet& maps, const MeshExportOptions& options) {
  if (options.voxel_size > 0) return options.voxel_size;
  double edge = 0;
  for (int a = 0; a < 3; ++a)
    edge = std::max(edge, glm::length(glm::dvec3(maps.world_from_box[a])));
  return edge / options.resolution;
}

// The field on every sample of `g`, in two passes: first the samples with
// even indices, then each other sample only where the even samples around
// it (its 2x2x2 cell of them) are not all clamped to the same side of the
// band; elsewhere it takes their value. Only the narrow band is evaluated
// densely; a part thinner than two voxels that no even sample reaches can
// be missed, as a grid of half the resolution would miss it.
template <typename At>
void FillField(const ObjectField& field, const Grid& g, float band, const At& at) {
  auto eval = [&](int i, int j, int k) {
    at(i, j, k) = static_cast<float>(field(g.origin + g.h * glm::dvec3(i, j, k)));
  };
  tbb::parallel_for(tbb::blocked_range<int>(0, (g.dims.x + 1) / 2), [&](const auto& r) {
    for (int i = 2 * r.begin(); i < 2 * r.end(); i += 2) {
      for (int j = 0; j < g.dims.y; j += 2) {
        for (int k = 0; k < g.dims.z; k += 2) eval(i, j, k);
      }
    }
  });
  tbb::parallel_for(tbb::blocked_range<int>(0, g.dims.x), [&](const auto& r) {
    for (int i = r.begin(); i != r.end(); ++i) {
      for (int j = 0; j < g.dims.y; ++j) {
        for (int k = 0; k < g.dims.z; ++k) {
          if (i % 2 == 0 && j % 2 == 0 && k % 2 == 0) continue;
          const int i0 = i & ~1, j0 = j & ~1, k0 = k & ~1;
          const int i1 = i % 2 ? i0 + 2 : i0, j1 = j % 2 ? j0 + 2 : j0, k1 = k % 2 ? k0 + 2 : k0;
          const float first = at(i0, j0, k0);
          bool saturated = std::abs(first) >= band;
          for (int c = 1; c < 8 && saturated; ++c) {
            saturated = at(c & 1 ? i1 : i0, c & 2 ? j1 : j0, c & 4 ? k1 : k0) == first;
          }
          if (saturated) {
            at(i, j, k) = first;
          } else {
            eval(i, j, k);
          }
        }
      }
    }
  });
}

// The colour one map gives point p: the fraction of its bilinear footprint
// whose texels saw p (residual within `tolerance`) and their colour
// (VdtSeenColor of depth_object_resolve.frag.glsl, with a hard tolerance).
double SeenColour(const FieldMap& m, Method method, const glm::dvec3& p, double tolerance,
                  glm::dvec3& colour, double& nearest, glm::dvec3& nearest_colour) {
  colour = glm::dvec3(0.0);
  const Lookup l = Project(m, p);
  if (!l.inside) return 0;
  const Footprint f = FootprintAt(m.map->camera, l.u, l.v);
  double seen = 0;
  for (int k = 0; k < 4; ++k) {
    const float d = m.Code(f.col[k], f.row[k]);
    double residual = kInf;
    if (d >= 0) {
      if (method == Method::kVisualHull) {
        residual = d == 0 ? 0.0 : std::max(l.q.z - d, 0.0);
      } else if (d > 0) {
        residual = std::abs(l.q.z - d);
      }
    }
    const size_t i = (static_cast<size_t>(f.row[k]) * m.map->camera.width + f.col[k]) * 4;
    const glm::dvec3 c(m.rgba[i], m.rgba[i + 1], m.rgba[i + 2]);
    if (residual < nearest) {
      nearest = residual;
      nearest_colour = c;
    }
    if (residual <= tolerance) {
      seen += f.weight[k];
      colour += f.weight[k] * c;
    }
  }
  if (seen > 0) colour /= seen;
  return seen;
}

glm::dvec3 LookDirection(const FieldMap& m, const glm::dvec3& p) {
  const glm::dvec3 axis = CameraAxis(m.cam_from_world);
  if (m.map->camera.orthographic) return axis;
  const glm::dvec3 d = p - CameraCentre(m.cam_from_world);
  return glm::length(d) > 0 ? glm::normalize(d) : axis;
}

std::vector<glm::u8vec3> VertexColours(const ObjectField& field, const core::TriangleMesh& mesh,
                                       Method method, double tolerance) {
  std::vector<glm::u8vec3> colours(mesh.positions.size());
  const std::vector<FieldMap>& maps = field.maps();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, mesh.positions.size()), [&](const auto& r) {
    std::vector<glm::dvec3> dirs(maps.size());
    for (size_t v = r.begin(); v != r.end(); ++v) {
      const glm::dvec3 p(mesh.positions[v]), n(mesh.normals[v]);
      for (size_t i = 0; i < maps.size(); ++i) dirs[i] = LookDirection(maps[i], p);
      const std::vector<float> w = ViewDependentWeights(dirs, -n);
      glm::dvec3 sum(0.0), any_sum(0.0), nearest_colour(128.0);
      double wsum = 0, any = 0, nearest = kInf;
      for (size_t i = 0; i < maps.size(); ++i) {
        glm::dvec3 c;
        const double seen = SeenColour(maps[i], method, p, tolerance, c, nearest, nearest_colour);
        sum += w[i] * seen * c;
        wsum += w[i] * seen;
        // Fallback where no weighted map saw p: any map that did, by how
        // squarely it looks at the surface.
        const double facing = std::max(glm::dot(-dirs[i], n), 0.01);
        any_sum += facing * seen * c;
        any += facing * seen;
      }
      const glm::dvec3 c = wsum > 0 ? sum / wsum : any > 0 ? any_sum / any : nearest_colour;
      colours[v] = glm::u8vec3(glm::clamp(glm::round(c), 0.0, 255.0));
    }
  });
  return colours;
}

// Moves each vertex onto the zero set of the field along its normal: a
// bracket of one, then two voxels each side, then `steps` bisections and a
// final linear interpolation of the field (a step field: the midpoint).
int64_t RefineVertices(const ObjectField& field, double h, int steps, core::TriangleMesh& mesh) {
  std::atomic<int64_t> refined{0};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, mesh.positions.size()), [&](const auto& r) {
    int64_t local = 0;
    for (size_t v = r.begin(); v != r.end(); ++v) {
      const glm::dvec3 p(mesh.positions[v]), n(mesh.normals[v]);
      const double f0 = field(p);
      glm::dvec3 in, out;
      double f_in = 0, f_out = 0;
      bool found = false;
      for (double a : {h, 2 * h}) {
        const glm::dvec3 q = f0 <= 0 ? p + a * n : p - a * n;
        const double fq = field(q);
        if ((fq <= 0) != (f0 <= 0)) {
          in = f0 <= 0 ? p : q;
          out = f0 <= 0 ? q : p;
          f_in = std::min(f0, fq);
          f_out = std::max(f0, fq);
          found = true;
          break;
        }
      }
      if (!found) continue;
      for (int s = 0; s < steps; ++s) {
        const glm::dvec3 mid = 0.5 * (in + out);
        const double fm = field(mid);
        if (fm <= 0) {
          in = mid;
          f_in = fm;
        } else {
          out = mid;
          f_out = fm;
        }
      }
      const double band = field.band();
      const double t =
          (f_in > -band && f_out < band && f_out > f_in) ? -f_in / (f_out - f_in) : 0.5;
      mesh.positions[v] = glm::vec3(in + t * (out - in));
      ++local;
    }
    refined += local;
  });
  return refined.load();
}

}  // namespace

std::function<double(const glm::dvec3&)> MakeObjectField(const MapSet& maps,
                                                         const MeshExportOptions& options,
                                                         double band) {
  CheckMapsFor(maps, options.method);
  const OutsidePolicy outside =
      options.outside ? *options.outside : ChooseOutsidePolicy(maps).policy;
  auto field = std::make_shared<const ObjectField>(maps, options, outside, band);
  return [field](const glm::dvec3& p) { return (*field)(p); };
}

MeshColouring MeshColouringFromName(const std::string& name) {
  return core::EnumFromName(kMeshColouringNames, name, "--colour", "colouring");
}

void MeshExportOptions::Check() const {
  if (resolution < 8 || resolution > 2048) {
    core::ThrowInputError("--resolution", "{} voxels is outside 8..2048", resolution);
  }
  if (robust_k < 0) core::ThrowInputError("--robust", "{} must be >= 0", robust_k);
  if (!(voxel_size >= 0) || !std::isfinite(voxel_size)) {
    core::ThrowInputError("MeshExportOptions", "voxel size {} must be >= 0", voxel_size);
  }
  if (refine_steps < 0 || refine_steps > 60) {
    core::ThrowInputError("MeshExportOptions", "refine steps {} outside 0..60", refine_steps);
  }
  if (!(subtexel_edge > 0)) core::ThrowInputError("MeshExportOptions", "subtexel edge must be > 0");
}

uint64_t EstimateMeshExportBytes(const MapSet& maps, const MeshExportOptions& options) {
  const Grid g = MakeGrid(maps, VoxelOf(maps, options));
  uint64_t texels = 0;
  for (const ImageMap& m : maps.maps)
    texels += static_cast<uint64_t>(m.camera.width) * m.camera.height;
  // Dense field (float) + the OpenVDB copy of its non-background voxels (at
  // most every voxel, with leaf overhead) + the surface: about 6 (dims)^2
  // vertices of positions, normals, colours and two triangles each.
  const uint64_t dmax = std::max({g.dims.x, g.dims.y, g.dims.z});
  return g.count() * (4 + 5) + texels * 5 + 6 * dmax * dmax * (12 + 12 + 3 + 24 + 16);
}

ColouredMesh ExtractObjectMesh(const MapSet& maps, const MeshExportOptions& options,
                               MeshExportStats* stats) {
  options.Check();
  CheckMapsFor(maps, options.method);
  MeshExportStats local;
  MeshExportStats& st = stats ? *stats : local;
  st = MeshExportStats{};
  const std::string where = "ibr export mesh: '" + maps.source + "'";
  core::CheckMemory(EstimateMeshExportBytes(maps, options), where,
                    fmt::format("the field grid at resolution {}", options.resolution));
  OutsidePolicy outside;
  if (options.outside) {
    outside = *options.outside;
    st.outside = "given";
  } else {
    const OutsideChoice choice = ChooseOutsidePolicy(maps);
    outside = choice.policy;
    st.outside = choice.reason;
  }
  const Grid g = MakeGrid(maps, VoxelOf(maps, options));
  st.grid = g.dims;
  st.voxel_size = g.h;
  const double band = kBandVoxels * g.h;

  auto t0 = std::chrono::steady_clock::now();
  const ObjectField field(maps, options, outside, band);
  // The field in the grid's index space (OpenVDB's Dense, z fastest).
  const openvdb::CoordBBox bbox(openvdb::Coord(0, 0, 0),
                                openvdb::Coord(g.dims.x - 1, g.dims.y - 1, g.dims.z - 1));
  openvdb::tools::Dense<float, openvdb::tools::LayoutZYX> dense(bbox, static_cast<float>(band));
  float* data = dense.data();
  FillField(field, g, static_cast<float>(band), [&](int i, int j, int k) -> float& {
    return data[dense.coordToOffset(openvdb::Coord(i, j, k))];
  });
  st.field_s = Seconds(t0);

  t0 = std::chrono::steady_clock::now();
  openvdb::initialize();
  openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(static_cast<float>(band));
  openvdb::tools::copyFromDense(dense, *grid, /*tolerance=*/0.0f);
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(*grid, points, triangles, quads, /*isovalue=*/0.0,
                               /*adaptivity=*/0.0);
  grid.reset();
  ColouredMesh out;
  core::TriangleMesh& mesh = out.mesh;
  mesh.positions.reserve(points.size());
  for (const openvdb::Vec3s& p : points) {
    mesh.positions.push_back(glm::vec3(g.origin + g.h * glm::dvec3(p.x(), p.y(), p.z())));
  }
  // volumeToMesh winds its polygons counter-clockwise seen from the positive
  // (outside) side, core::TriangleMesh's convention (checked by the signed
  // volume in tests/ibr/mesh_export_test).
  mesh.indices.reserve(3 * triangles.size() + 6 * quads.size());
  for (const openvdb::Vec3I& t : triangles)
    mesh.indices.insert(mesh.indices.end(), {t[0], t[1], t[2]});
  for (const openvdb::Vec4I& q : quads) {
    mesh.indices.insert(mesh.indices.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
  }
  st.extract_s = Seconds(t0);
  if (mesh.indices.empty()) {
    core::ThrowInputError(where, "the {} is empty at resolution {} (no surface in the box)",
                          MethodName(options.method), options.resolution);
  }
  core::SetAreaWeightedNormals(mesh);

  t0 = std::chrono::steady_clock::now();
  if (options.refine_steps > 0) {
    st.refined = RefineVertices(field, g.h, options.refine_steps, mesh);
    core::SetAreaWeightedNormals(mesh);
  }
  st.refine_s = Seconds(t0);

  t0 = std::chrono::steady_clock::now();
  if (options.colouring == MeshColouring::kViewDependent) {
    double texel = 0;
    for (const ImageMap& m : maps.maps) {
      if (m.camera.orthographic) texel = std::max(texel, 1.0 / m.camera.fx);
    }
    out.colours = VertexColours(field, mesh, options.method, std::max(2 * g.h, 2 * texel));
  }
  st.colour_s = Seconds(t0);
  return out;
}

ColouredMesh FusedPointCloud(const MapSet& maps, const MeshExportOptions& options,
                             double tolerance_texels) {
  const std::string where = "ibr export points: '" + maps.source + "'";
  uint64_t valid = 0;
  for (const ImageMap& m : maps.maps) {
    for (size_t i = 0; i < m.depth.values().size(); ++i) {
      const float d = m.depth.values()[i];
      valid += std::isfinite(d) && d > 0;
    }
  }
  if (valid == 0) core::ThrowInputError(where, "no view has valid depth (points need depth maps)");
  core::CheckMemory(valid * (12 + 12 + 3), where, fmt::format("{} points", valid));
  MeshExportOptions o = options;
  o.method = Method::kDepthObject;
  o.invalid_depth = InvalidDepthPolicy::kNoConstraint;  // a hole in one map does not drop points
  const OutsidePolicy outside = o.outside ? *o.outside : ChooseOutsidePolicy(maps).policy;
  const ObjectField field(maps, o, outside, kInf);
  ColouredMesh out;
  for (const FieldMap& m : field.maps()) {
    const MapCamera& c = m.map->camera;
    auto point = [&](int col, int row, double d) {
      const double x = (col + 0.5 - c.cx) / c.fx, y = (row + 0.5 - c.cy) / c.fy;
      const glm::dvec3 q = c.orthographic ? glm::dvec3(x, y, d) : glm::dvec3(x * d, y * d, d);
      return glm::dvec3(m.world_from_cam * glm::dvec4(q, 1.0));
    };
    const size_t first = out.mesh.positions.size();
    out.mesh.positions.resize(first + c.width * static_cast<size_t>(c.height));
    std::vector<uint8_t> keep(c.width * static_cast<size_t>(c.height), 0);
    std::vector<glm::vec3> normals(keep.size());
    tbb::parallel_for(tbb::blocked_range<int>(0, c.height), [&](const auto& r) {
      for (int row = r.begin(); row != r.end(); ++row) {
        for (int col = 0; col < c.width; ++col) {
          const float d = m.Code(col, row);
          if (!(d > 0)) continue;
          const glm::dvec3 p = point(col, row, d);
          const double texel = TexelSize(c, d);
          // The other maps must not carve it (the point's own map gives 0).
          if (field(p) > tolerance_texels * texel) continue;
          // Normal: central differences over neighbours on the same surface.
          auto neighbour = [&](int dc, int dr, glm::dvec3& q) {
            const int cc = std::clamp(col + dc, 0, c.width - 1),
                      rr = std::clamp(row + dr, 0, c.height - 1);
            const float dn = m.Code(cc, rr);
            if (!(dn > 0) || std::abs(dn - d) > options.subtexel_edge * texel) return false;
            q = point(cc, rr, dn);
            return (cc != col || rr != row);
          };
          glm::dvec3 a, b, e, f;
          const glm::dvec3 du =
              neighbour(1, 0, a) ? a - p : (neighbour(-1, 0, b) ? p - b : glm::dvec3(0));
          const glm::dvec3 dv =
              neighbour(0, 1, e) ? e - p : (neighbour(0, -1, f) ? p - f : glm::dvec3(0));
          glm::dvec3 n = glm::cross(du, dv);
          const glm::dvec3 to_camera = -LookDirection(m, p);
          if (glm::length(n) == 0) n = to_camera;
          n = glm::normalize(n);
          if (glm::dot(n, to_camera) < 0) n = -n;
          const size_t i = static_cast<size_t>(row) * c.width + col;
          out.mesh.positions[first + i] = glm::vec3(p);
          normals[i] = glm::vec3(n);
          keep[i] = 1;
        }
      }
    });
    size_t w = first;
    for (size_t i = 0; i < keep.size(); ++i) {
      if (!keep[i]) continue;
      out.mesh.positions[w++] = out.mesh.positions[first + i];
      out.mesh.normals.push_back(normals[i]);
      out.colours.emplace_back(m.rgba[4 * i], m.rgba[4 * i + 1], m.rgba[4 * i + 2]);
    }
    out.mesh.positions.resize(w);
  }
  if (out.mesh.positions.empty()) {
    core::ThrowInputError(where, "every depth texel is carved by another view (no points left)");
  }
  return out;
}

double DatasetVoxelSize(const glm::dvec3& bounds_extent, int resolution) {
  return std::max({bounds_extent.x, bounds_extent.y, bounds_extent.z}) / resolution;
}

ExportSummary ExportDatasetMesh(const std::filesystem::path& dataset_dir,
                                const std::filesystem::path& out, MeshExportOptions options) {
  options.Check();
  core::CheckMeshFilePath("ibr export mesh", out);
  const capture::Dataset dataset = ReadMapDataset(dataset_dir);
  const MapSet maps = MapsFromDataset(dataset);
  if (options.voxel_size == 0 && dataset.bounds) {
    options.voxel_size = DatasetVoxelSize(dataset.bounds->extent(), options.resolution);
  }
  ExportSummary s;
  s.views = static_cast<int>(maps.maps.size());
  const ColouredMesh mesh = ExtractObjectMesh(maps, options, &s.stats);
  core::WriteMeshFile(out, mesh.mesh, mesh.colours);
  s.vertices = static_cast<int64_t>(mesh.mesh.positions.size());
  s.triangles = static_cast<int64_t>(mesh.mesh.triangle_count());
  s.volume = core::SignedVolume(mesh.mesh);
  return s;
}

ExportSummary ExportDatasetPoints(const std::filesystem::path& dataset_dir,
                                  const std::filesystem::path& out) {
  core::CheckMeshFilePath("ibr export points", out, /*allow_obj=*/false);
  const capture::Dataset dataset = ReadMapDataset(dataset_dir);
  const MapSet maps = MapsFromDataset(dataset);
  const ColouredMesh points = FusedPointCloud(maps, MeshExportOptions{});
  core::WriteMeshFile(out, points.mesh, points.colours);
  ExportSummary s;
  s.views = static_cast<int>(maps.maps.size());
  s.vertices = static_cast<int64_t>(points.mesh.positions.size());
  return s;
}

}  // namespace ibr
