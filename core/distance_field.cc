#include "core/distance_field.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <limits>
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

namespace {

// Disjoint sets over 0..n-1 (path halving).
class UnionFind {
 public:
  explicit UnionFind(size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0u); }
  uint32_t Find(uint32_t x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void Join(uint32_t a, uint32_t b) { parent_[Find(a)] = Find(b); }

 private:
  std::vector<uint32_t> parent_;
};

}  // namespace

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
  // Loops = connected components of the boundary edges.
  UnionFind loops(mesh.positions.size());
  MeshBoundary boundary;
  std::vector<uint32_t> boundary_vertices;
  for (const auto& [edge, uses] : edge_uses) {
    if (uses >= 3) ++boundary.nonmanifold_edges;
    if (uses != 1) continue;
    ++boundary.boundary_edges;
    loops.Join(edge.first, edge.second);
    boundary_vertices.push_back(edge.first);
    boundary_vertices.push_back(edge.second);
  }
  std::sort(boundary_vertices.begin(), boundary_vertices.end());
  boundary_vertices.erase(std::unique(boundary_vertices.begin(), boundary_vertices.end()),
                          boundary_vertices.end());
  for (uint32_t v : boundary_vertices) boundary.boundary_loops += loops.Find(v) == v ? 1 : 0;
  return boundary;
}

bool IsClosedOutward(const TriangleMesh& mesh) {
  const size_t n = mesh.triangle_count();
  if (n == 0) return false;
  // Weld bit-equal positions: sort the vertices by position, number the
  // distinct ones (sorted vectors: the pass runs this on every rebuild).
  std::vector<uint32_t> by_position(mesh.positions.size());
  std::iota(by_position.begin(), by_position.end(), 0u);
  const auto key = [&](uint32_t v) {
    const glm::vec3& p = mesh.positions[v];
    return std::array<float, 3>{p.x, p.y, p.z};
  };
  std::sort(by_position.begin(), by_position.end(),
            [&](uint32_t a, uint32_t b) { return key(a) < key(b); });
  std::vector<uint32_t> weld(mesh.positions.size());
  uint32_t id = 0;
  for (size_t k = 0; k < by_position.size(); ++k) {
    if (k > 0 && key(by_position[k]) != key(by_position[k - 1])) ++id;
    weld[by_position[k]] = id;
  }
  // Directed edges (from << 32 | to) with their triangle, sorted.
  std::vector<std::pair<uint64_t, uint32_t>> edges;
  edges.reserve(3 * n);
  for (uint32_t t = 0; t < n; ++t) {
    const uint32_t v[3] = {weld[mesh.indices[3 * t]], weld[mesh.indices[3 * t + 1]],
                           weld[mesh.indices[3 * t + 2]]};
    if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) return false;
    for (int e = 0; e < 3; ++e) edges.emplace_back(uint64_t{v[e]} << 32 | v[(e + 1) % 3], t);
  }
  std::sort(edges.begin(), edges.end());
  for (size_t k = 1; k < edges.size(); ++k) {
    if (edges[k].first == edges[k - 1].first) return false;  // a directed edge used twice
  }
  // Every edge's reverse, in a triangle of the same component.
  UnionFind components(n);
  for (const auto& [edge, t] : edges) {
    const uint64_t reverse = edge << 32 | edge >> 32;
    const auto it =
        std::lower_bound(edges.begin(), edges.end(), std::pair<uint64_t, uint32_t>{reverse, 0u});
    if (it == edges.end() || it->first != reverse) return false;
    components.Join(t, it->second);
  }
  // Six times each component's signed volume (divergence theorem, double).
  std::vector<double> volume(n, 0.0);
  for (uint32_t t = 0; t < n; ++t) {
    const glm::dvec3 a(mesh.positions[mesh.indices[3 * t]]);
    const glm::dvec3 b(mesh.positions[mesh.indices[3 * t + 1]]);
    const glm::dvec3 c(mesh.positions[mesh.indices[3 * t + 2]]);
    volume[components.Find(t)] += glm::dot(a, glm::cross(b, c));
  }
  for (uint32_t t = 0; t < n; ++t) {
    if (components.Find(t) == t && !(volume[t] > 0)) return false;
  }
  return true;
}

void DistanceFieldOptions::Check() const {
  if (resolution < 2 || resolution > 1024) {
    ThrowInputError("DistanceFieldOptions", "resolution {} outside 2..1024", resolution);
  }
  if (threads < 0 || threads > 256)
    ThrowInputError("DistanceFieldOptions", "threads {} outside 0..256", threads);
}

namespace {

// Trilinear interpolation of the corner values c[z][y][x] at fractions f in
// [0, 1]^3 (x first, then y, then z).
double Trilinear(const double c[2][2][2], const glm::dvec3& f) {
  auto lerp = [](double a, double b, double t) { return a + (b - a) * t; };
  const double y0 = lerp(lerp(c[0][0][0], c[0][0][1], f.x), lerp(c[0][1][0], c[0][1][1], f.x), f.y);
  const double y1 = lerp(lerp(c[1][0][0], c[1][0][1], f.x), lerp(c[1][1][0], c[1][1][1], f.x), f.y);
  return lerp(y0, y1, f.z);
}

}  // namespace

// BuildDistanceField's blocks: kBlock^3 voxels whose far-from-surface nodes
// are interpolated from the block's corners.
constexpr int kBlock = 4;

double DistanceField::LookupOverestimate() const {
  // A node interpolated from its block's corners exceeds its distance by at
  // most sum w_c |c - x| <= the half diagonal (at the block's centre).
  const double blocks = std::isfinite(exact_band) ? 0.5 * kBlock : 0.0;
  return std::sqrt(3.0) * spacing * (1.0 + blocks);
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
  return Trilinear(c, f);
}

namespace {

// The exact corners of a block near the surface: c[z][y][x] at nodes
// lo / hi per axis (hi - lo = the block's span).
struct BlockCorners {
  double c[2][2][2];
  glm::ivec3 lo, hi;
};

// Signed distances along one row of nodes (i0..i1 inclusive at y = j,
// z = k) of a block near the surface. A node x whose distance is provably
// beyond the band needs no query: for any node y of known exact distance
// d_y (the block's corners, the row's last queried node), |d(x)| >= |d_y| -
// |x - y| =: L, and when L > band no surface separates x from y (every point
// between them is at least L from it), so x has y's sign and takes max(L,
// the corners' trilinear |d|): beyond the band, within half a block diagonal
// above the truth (an interpolated block's bound, LookupOverestimate). The
// others get an exact query. The sign of a queried node carries over from
// its neighbour unless the segment between them can cross the surface: a
// crossing point s gives d_a <= |a - s| and d_b <= |b - s|, so it needs d_a +
// d_b <= spacing; only then is the (costlier) inside test run.
// `previous_bound` > 0: node i0 - 1 is already written, its true distance at
// least that, and its sign exact. (1e-6: the stored float distances are
// rounded.) Returns the number of closest-point queries made.
int64_t ExactRow(const MeshDistance& distance, DistanceField& field, const BlockCorners& block,
                 int i0, int i1, int j, int k, double previous_bound) {
  const size_t row = field.Index(0, j, k);
  const double margin = field.spacing * 1e-6;
  double bound = previous_bound;
  bool previous_inside = previous_bound > 0 && field.values[row + i0 - 1] < 0;
  int last_exact = -1;  // the row's last queried node, its distance
  double last_distance = 0.0;
  int64_t queries = 0;
  for (int i = i0; i <= i1; ++i) {
    const glm::ivec3 node(i, j, k);
    // The best lower bound from an exact node, and that node's sign.
    double lower = -1.0;
    bool lower_inside = false;
    double magnitude[2][2][2];
    for (int dz = 0; dz < 2; ++dz)
      for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx) {
          const double c = block.c[dz][dy][dx];
          const glm::ivec3 corner(dx ? block.hi.x : block.lo.x, dy ? block.hi.y : block.lo.y,
                                  dz ? block.hi.z : block.lo.z);
          const double l =
              std::abs(c) * (1 - 1e-6) - field.spacing * glm::length(glm::dvec3(node - corner));
          if (l > lower) {
            lower = l;
            lower_inside = c < 0;
          }
          magnitude[dz][dy][dx] = std::abs(c);
        }
    if (last_exact >= 0) {
      const double l = last_distance * (1 - 1e-6) - field.spacing * (i - last_exact);
      if (l > lower) {
        lower = l;
        lower_inside = field.values[row + last_exact] < 0;
      }
    }
    if (lower > field.exact_band + margin) {
      const glm::dvec3 f = glm::dvec3(node - block.lo) / glm::dvec3(block.hi - block.lo);
      const double d = std::max(lower, Trilinear(magnitude, f));
      field.values[row + i] = static_cast<float>(lower_inside ? -d : d);
      bound = lower;
      previous_inside = lower_inside;
      continue;
    }
    const glm::dvec3 p = field.origin + field.spacing * glm::dvec3(node);
    const double d = distance.UnsignedDistance(p);
    ++queries;
    const bool inside = (bound > 0 && bound + d > field.spacing * (1 + 1e-6)) ? previous_inside
                                                                              : distance.Inside(p);
    field.values[row + i] = static_cast<float>(inside ? -d : d);
    bound = d;
    previous_inside = inside;
    last_exact = i;
    last_distance = d;
  }
  return queries;
}

}  // namespace

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

  // Blocks of kBlock^3 voxels; block b spans nodes b * kBlock .. min((b + 1)
  // kBlock, n - 1) per axis (neighbours share their face nodes); the blocks
  // are also the unit of work of the threads.
  const bool banded = options.exact_band_voxels > 0;
  const glm::ivec3 blocks = (field.size - 2) / kBlock + 1;
  field.exact_band =
      banded ? options.exact_band_voxels * field.spacing : std::numeric_limits<double>::infinity();
  auto span = [&](int b, int axis) {
    return glm::ivec2(b * kBlock, std::min((b + 1) * kBlock, field.size[axis] - 1));
  };

  int threads =
      options.threads > 0 ? options.threads : static_cast<int>(std::thread::hardware_concurrency());
  threads = std::max(threads, 1);
  auto parallel = [&](int count, const auto& work) {
    std::atomic<int> next{0};
    auto worker = [&] {
      for (int n = next++; n < count; n = next++) work(n);
    };
    std::vector<std::thread> pool;
    for (int t = 1; t < std::min(threads, count); ++t) pool.emplace_back(worker);
    worker();
    for (std::thread& t : pool) t.join();
  };

  // 1. Exact signed distances at the block corners (corner c of an axis is
  // node c * kBlock, the last one node n - 1), in their own array.
  const glm::ivec3 corner_count = blocks + 1;
  std::vector<float> corners;
  auto corner_node = [&](int c, int axis) { return std::min(c * kBlock, field.size[axis] - 1); };
  std::atomic<int64_t> queries{0};
  if (banded) {
    corners.resize(static_cast<size_t>(corner_count.x) * corner_count.y * corner_count.z);
    parallel(corner_count.y * corner_count.z, [&](int row) {
      const int cy = row % corner_count.y, cz = row / corner_count.y;
      for (int cx = 0; cx < corner_count.x; ++cx) {
        const glm::dvec3 p =
            field.origin +
            field.spacing * glm::dvec3(corner_node(cx, 0), corner_node(cy, 1), corner_node(cz, 2));
        corners[GridIndex(corner_count, cx, cy, cz)] =
            static_cast<float>(distance.SignedDistance(p));
      }
      queries += corner_count.x;
    });
  }

  // 2. Per block: far from the surface, i.e. every corner farther than the
  // band plus half the block's diagonal. Every node x lies within half a
  // diagonal of some corner c, so |d(x)| >= |d(c)| - |x - c| > band, and no
  // surface separates x from c; neighbouring corners (one block side apart,
  // less than the sum of their distances) share their sign, so the block
  // holds no crossing. Its nodes take the corners' trilinear interpolation:
  // the common sign, magnitude > band, within a diagonal of the truth (each
  // corner's distance is). Other blocks take exact rows. A block writes the
  // nodes it owns: its span without the upper faces, except at the grid's end.
  const double half_diagonal = 0.5 * std::sqrt(3.0) * kBlock * field.spacing;
  std::atomic<int> done_slabs{0};
  parallel(blocks.z, [&](int bz) {
    const glm::ivec2 sz = span(bz, 2);
    for (int by = 0; by < blocks.y; ++by) {
      const glm::ivec2 sy = span(by, 1);
      bool previous_far = false;  // block bx - 1 of this block row was interpolated
      for (int bx = 0; bx < blocks.x; ++bx) {
        const glm::ivec2 sx = span(bx, 0);
        const int x1 = sx.y == field.size.x - 1 ? sx.y : sx.y - 1;
        const int y1 = sy.y == field.size.y - 1 ? sy.y : sy.y - 1;
        const int z1 = sz.y == field.size.z - 1 ? sz.y : sz.y - 1;
        double c[2][2][2] = {};
        double nearest = 1e300;
        if (banded) {
          for (int dz = 0; dz < 2; ++dz)
            for (int dy = 0; dy < 2; ++dy)
              for (int dx = 0; dx < 2; ++dx) {
                c[dz][dy][dx] = corners[GridIndex(corner_count, bx + dx, by + dy, bz + dz)];
                nearest = std::min(nearest, std::abs(c[dz][dy][dx]));
              }
        }
        // What ExactRow may assume of the node before this block's rows.
        const double previous_bound = bx == 0 ? 0.0 : previous_far ? field.exact_band : -1.0;
        previous_far = banded && nearest > field.exact_band + half_diagonal;
        if (previous_far) {
          for (int k = sz.x; k <= z1; ++k)
            for (int j = sy.x; j <= y1; ++j)
              for (int i = sx.x; i <= x1; ++i) {
                const glm::dvec3 f(double(i - sx.x) / (sx.y - sx.x),
                                   double(j - sy.x) / (sy.y - sy.x),
                                   double(k - sz.x) / (sz.y - sz.x));
                field.values[field.Index(i, j, k)] = static_cast<float>(Trilinear(c, f));
              }
          continue;
        }
        BlockCorners corners_of_block;
        std::copy(&c[0][0][0], &c[0][0][0] + 8, &corners_of_block.c[0][0][0]);
        corners_of_block.lo = glm::ivec3(sx.x, sy.x, sz.x);
        corners_of_block.hi = glm::ivec3(sx.y, sy.y, sz.y);
        int64_t block_queries = 0;
        for (int k = sz.x; k <= z1; ++k)
          for (int j = sy.x; j <= y1; ++j) {
            // The node before: exact when within the band, else (exact or
            // skipped by ExactRow) its true distance exceeds the band.
            const double bound =
                previous_bound < 0
                    ? std::min(std::abs(double(field.At(sx.x - 1, j, k))), field.exact_band)
                    : previous_bound;
            block_queries += ExactRow(distance, field, corners_of_block, sx.x, x1, j, k, bound);
          }
        queries += block_queries;
      }
    }
    const int done = ++done_slabs;
    if (options.progress && (done % std::max(1, blocks.z / 10) == 0 || done == blocks.z)) {
      std::fprintf(stderr, "distance field %dx%dx%d: %d/%d slabs\n", field.size.x, field.size.y,
                   field.size.z, done, blocks.z);
    }
  });
  field.distance_queries = queries;
  return field;
}

DistanceField BuildDistanceField(const TriangleMesh& mesh, const Box3d& box,
                                 const DistanceFieldOptions& options, const std::string& where) {
  options.Check();
  MeshDistance distance(mesh, options.cap_holes, where);
  return BuildDistanceField(distance, box, options);
}

}  // namespace core
