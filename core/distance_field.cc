#include "core/distance_field.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <thread>
#include <tuple>

#include "core/check.h"
#include "core/error.h"

namespace core {

std::vector<uint32_t> WeldVertices(const std::vector<glm::vec3>& positions, double tolerance) {
  std::vector<uint32_t> weld(positions.size());
  if (positions.empty()) return weld;
  if (tolerance < 0) {
    glm::dvec3 lo(positions[0]), hi(positions[0]);
    for (const glm::vec3& p : positions) {
      lo = glm::min(lo, glm::dvec3(p));
      hi = glm::max(hi, glm::dvec3(p));
    }
    tolerance = 1e-6 * glm::length(hi - lo);
  }
  // Hash grid of cell size `tolerance` (at least a float ulp-scale cell):
  // candidates sit in the 27 neighbouring cells.
  double cell = std::max(tolerance, 1e-30);
  std::map<std::tuple<int64_t, int64_t, int64_t>, std::vector<uint32_t>> grid;
  auto key = [&](const glm::dvec3& p, int dx, int dy, int dz) {
    return std::make_tuple(static_cast<int64_t>(std::floor(p.x / cell)) + dx,
                           static_cast<int64_t>(std::floor(p.y / cell)) + dy,
                           static_cast<int64_t>(std::floor(p.z / cell)) + dz);
  };
  for (size_t v = 0; v < positions.size(); ++v) {
    glm::dvec3 p(positions[v]);
    uint32_t found = static_cast<uint32_t>(v);
    for (int dz = -1; dz <= 1 && found == v; ++dz)
      for (int dy = -1; dy <= 1 && found == v; ++dy)
        for (int dx = -1; dx <= 1 && found == v; ++dx) {
          auto it = grid.find(key(p, dx, dy, dz));
          if (it == grid.end()) continue;
          for (uint32_t w : it->second) {
            if (glm::length(glm::dvec3(positions[w]) - p) <= tolerance) {
              found = w;
              break;
            }
          }
        }
    weld[v] = found;
    if (found == v) grid[key(p, 0, 0, 0)].push_back(found);
  }
  return weld;
}

MeshBoundary FindMeshBoundary(const TriangleMesh& mesh) {
  std::vector<uint32_t> weld = WeldVertices(mesh.positions);
  std::map<std::pair<uint32_t, uint32_t>, int> edge_uses;
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    uint32_t v[3] = {weld[mesh.indices[3 * t]], weld[mesh.indices[3 * t + 1]],
                     weld[mesh.indices[3 * t + 2]]};
    if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) continue;  // collapsed by welding (poles)
    for (int e = 0; e < 3; ++e) {
      uint32_t a = v[e], b = v[(e + 1) % 3];
      ++edge_uses[{std::min(a, b), std::max(a, b)}];
    }
  }
  // Loops = connected components of the boundary edges (union-find).
  std::vector<uint32_t> parent(mesh.positions.size());
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  MeshBoundary boundary;
  std::vector<uint32_t> boundary_vertices;
  for (const auto& [edge, uses] : edge_uses) {
    if (uses >= 3) ++boundary.nonmanifold_edges;
    if (uses != 1) continue;
    ++boundary.boundary_edges;
    parent[find(edge.first)] = find(edge.second);
    boundary_vertices.push_back(edge.first);
    boundary_vertices.push_back(edge.second);
  }
  std::sort(boundary_vertices.begin(), boundary_vertices.end());
  boundary_vertices.erase(std::unique(boundary_vertices.begin(), boundary_vertices.end()),
                          boundary_vertices.end());
  for (uint32_t v : boundary_vertices) boundary.boundary_loops += find(v) == v ? 1 : 0;
  return boundary;
}

void DistanceFieldOptions::Check() const {
  if (resolution < 2 || resolution > 1024) {
    ThrowInputError("DistanceFieldOptions", "resolution {} outside 2..1024", resolution);
  }
  if (threads < 0 || threads > 256)
    ThrowInputError("DistanceFieldOptions", "threads {} outside 0..256", threads);
}

double DistanceField::Sample(const glm::dvec3& p) const {
  IBR_CHECK(!values.empty());
  glm::dvec3 g = glm::clamp((p - origin) / spacing, glm::dvec3(0.0), glm::dvec3(size - 1));
  glm::ivec3 i0 = glm::min(glm::ivec3(glm::floor(g)), glm::max(size - 2, glm::ivec3(0)));
  glm::dvec3 f = g - glm::dvec3(i0);
  glm::ivec3 i1 = glm::min(i0 + 1, size - 1);
  double c[2][2][2];
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx) {
        c[dz][dy][dx] = At(dx ? i1.x : i0.x, dy ? i1.y : i0.y, dz ? i1.z : i0.z);
      }
  auto lerp = [](double a, double b, double t) { return a + (b - a) * t; };
  double y0 = lerp(lerp(c[0][0][0], c[0][0][1], f.x), lerp(c[0][1][0], c[0][1][1], f.x), f.y);
  double y1 = lerp(lerp(c[1][0][0], c[1][0][1], f.x), lerp(c[1][1][0], c[1][1][1], f.x), f.y);
  return lerp(y0, y1, f.z);
}

DistanceField BuildDistanceField(const MeshDistance& distance, const Box3d& box,
                                 const DistanceFieldOptions& options) {
  options.Check();
  glm::dvec3 extent = box.size();
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(box.lo[a]) || !std::isfinite(box.hi[a]) || !(extent[a] > 0)) {
      ThrowInputError("BuildDistanceField", "box [{}, {}, {}]-[{}, {}, {}] is empty or not finite",
                      box.lo.x, box.lo.y, box.lo.z, box.hi.x, box.hi.y, box.hi.z);
    }
  }
  DistanceField field;
  double longest = std::max({extent.x, extent.y, extent.z});
  field.spacing = longest / (options.resolution - 1);
  for (int a = 0; a < 3; ++a) {
    field.size[a] = std::max(2, static_cast<int>(std::ceil(extent[a] / field.spacing - 1e-9)) + 1);
  }
  // Centre the grid on the box (it covers the box; the longest axis exactly).
  glm::dvec3 covered = field.spacing * glm::dvec3(field.size - 1);
  field.origin = box.lo - 0.5 * (covered - extent);
  field.values.assign(static_cast<size_t>(field.size.x) * field.size.y * field.size.z, 0.0f);

  int threads =
      options.threads > 0 ? options.threads : static_cast<int>(std::thread::hardware_concurrency());
  threads = std::clamp(threads, 1, field.size.z);
  std::atomic<int> next_slice{0}, done_slices{0};
  auto worker = [&] {
    for (int k = next_slice++; k < field.size.z; k = next_slice++) {
      for (int j = 0; j < field.size.y; ++j) {
        double previous = 0.0;
        for (int i = 0; i < field.size.x; ++i) {
          glm::dvec3 p = field.origin + field.spacing * glm::dvec3(i, j, k);
          double d = distance.UnsignedDistance(p);
          // The segment between two neighbouring samples crosses the surface
          // only if their distances sum to at most the spacing (a crossing
          // point s gives d_a <= |a - s| and d_b <= |b - s|). Otherwise the
          // sign carries over and the (costlier) inside test is skipped.
          bool inside = (i > 0 && std::abs(previous) + d > field.spacing * (1 + 1e-9))
                            ? previous < 0
                            : distance.Inside(p);
          previous = inside ? -d : d;
          field.values[(static_cast<size_t>(k) * field.size.y + j) * field.size.x + i] =
              static_cast<float>(previous);
        }
      }
      int done = ++done_slices;
      if (options.progress &&
          (done % std::max(1, field.size.z / 10) == 0 || done == field.size.z)) {
        std::fprintf(stderr, "distance field %dx%dx%d: %d/%d slices\n", field.size.x, field.size.y,
                     field.size.z, done, field.size.z);
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();
  return field;
}

DistanceField BuildDistanceField(const TriangleMesh& mesh, const Box3d& box,
                                 const DistanceFieldOptions& options, const std::string& where) {
  options.Check();
  MeshDistance distance(mesh, options.cap_holes, where);
  return BuildDistanceField(distance, box, options);
}

}  // namespace core
