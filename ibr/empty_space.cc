#include "ibr/empty_space.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/check.h"
#include "core/error.h"

namespace ibr {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Min-pyramid of one map's acceptance threshold: texel (col, row) accepts a
// point at map camera z iff z >= threshold (so +inf never accepts, -inf
// always does). Level 0 is the map's own size.
class MinPyramid {
 public:
  MinPyramid(std::vector<float> level0, int width, int height) {
    widths_.push_back(width);
    heights_.push_back(height);
    levels_.push_back(std::move(level0));
    while (widths_.back() > 1 || heights_.back() > 1) {
      const int w = widths_.back(), h = heights_.back();
      const int nw = (w + 1) / 2, nh = (h + 1) / 2;
      std::vector<float> next(static_cast<size_t>(nw) * nh);
      const std::vector<float>& prev = levels_.back();
      for (int y = 0; y < nh; ++y) {
        for (int x = 0; x < nw; ++x) {
          float m = kInf;
          for (int dy = 0; dy < 2; ++dy) {
            for (int dx = 0; dx < 2; ++dx) {
              const int sx = std::min(2 * x + dx, w - 1), sy = std::min(2 * y + dy, h - 1);
              m = std::min(m, prev[static_cast<size_t>(sy) * w + sx]);
            }
          }
          next[static_cast<size_t>(y) * nw + x] = m;
        }
      }
      widths_.push_back(nw);
      heights_.push_back(nh);
      levels_.push_back(std::move(next));
    }
  }
  // Minimum over texels [x0, x1] x [y0, y1] (inclusive, inside level 0), or
  // lower (a coarser level's cells may cover a few more texels: conservative).
  float Min(int x0, int x1, int y0, int y1) const {
    int level = 0;
    while ((x1 >> level) - (x0 >> level) > 1 || (y1 >> level) - (y0 >> level) > 1) ++level;
    const std::vector<float>& l = levels_[level];
    const int w = widths_[level];
    float m = kInf;
    for (int y = y0 >> level; y <= (y1 >> level); ++y) {
      for (int x = x0 >> level; x <= (x1 >> level); ++x)
        m = std::min(m, l[static_cast<size_t>(y) * w + x]);
    }
    return m;
  }

 private:
  std::vector<std::vector<float>> levels_;
  std::vector<int> widths_, heights_;
};

}  // namespace

void ChessboardDistance(int n, std::vector<uint8_t>& g) {
  IBR_CHECK_EQ(g.size(), static_cast<size_t>(n) * n * n);
  auto at = [&](int x, int y, int z) -> uint8_t& {
    return g[(static_cast<size_t>(z) * n + y) * n + x];
  };
  for (uint8_t& v : g) v = v == 0 ? 0 : 255;
  // Forward pass: the 13 neighbours already visited in raster order; backward:
  // the other 13. For the chessboard metric two passes are exact (Rosenfeld
  // and Pfaltz 1966). Neighbours outside the grid do not count as occupied.
  for (int pass = 0; pass < 2; ++pass) {
    const int s = pass == 0 ? 1 : -1;
    const int begin = pass == 0 ? 0 : n - 1, end = pass == 0 ? n : -1;
    for (int z = begin; z != end; z += s) {
      for (int y = begin; y != end; y += s) {
        for (int x = begin; x != end; x += s) {
          uint8_t& v = at(x, y, z);
          if (v == 0) continue;
          int best = v;
          for (int dz = -1; dz <= 0; ++dz) {
            for (int dy = -1; dy <= 1; ++dy) {
              for (int dx = -1; dx <= 1; ++dx) {
                // The half-neighbourhood before (x, y, z) in this pass's order.
                if (dz == 0 && (dy > 0 || (dy == 0 && dx >= 0))) continue;
                const int nx = x + s * dx, ny = y + s * dy, nz = z + s * dz;
                if (nx < 0 || ny < 0 || nz < 0 || nx >= n || ny >= n || nz >= n) continue;
                best = std::min(best, at(nx, ny, nz) + 1);
              }
            }
          }
          v = static_cast<uint8_t>(std::min(best, 255));
        }
      }
    }
  }
}

SkipGrid BuildSkipGrid(const MapSet& maps, const std::vector<float>& depth_codes, int layer_width,
                       int layer_height, const std::vector<int>& active,
                       const SkipGridPolicy& policy, int resolution) {
  IBR_CHECK_EQ(depth_codes.size(), maps.maps.size() * layer_width * layer_height);
  const auto codes_of = [&](int map_index, std::vector<float>& codes) {
    const ImageMap& m = maps.maps[map_index];
    const int w = m.camera.width, h = m.camera.height;
    IBR_CHECK_LE(w, layer_width);
    IBR_CHECK_LE(h, layer_height);
    codes.resize(static_cast<size_t>(w) * h);
    const float* layer =
        depth_codes.data() + static_cast<size_t>(map_index) * layer_width * layer_height;
    for (int row = 0; row < h; ++row) {
      std::copy_n(layer + static_cast<size_t>(row) * layer_width, w,
                  codes.data() + static_cast<size_t>(row) * w);
    }
  };
  return BuildSkipGrid(maps, codes_of, active, policy, resolution);
}

SkipGrid BuildSkipGrid(
    const MapSet& maps,
    const std::function<void(int map_index, std::vector<float>& codes)>& codes_of,
    const std::vector<int>& active, const SkipGridPolicy& policy, int resolution) {
  if (resolution < 1 || resolution > 255) {
    core::ThrowInputError("BuildSkipGrid", "resolution {} outside 1..255", resolution);
  }
  const int n = resolution;
  SkipGrid grid;
  grid.resolution = n;
  std::vector<uint8_t> rejections(static_cast<size_t>(n) * n * n, 0);

  // Depth tolerance (scene units): far above float rounding of the GPU's
  // view -> map transform, far below a texel's depth step.
  const glm::dvec3 diag(maps.world_from_box * glm::dvec4(1, 1, 1, 0));
  const double tol = 1e-4 * glm::length(diag);
  const int nv = n + 1;  // grid vertices per axis
  std::vector<glm::dvec3> uvz(static_cast<size_t>(nv) * nv * nv);
  std::vector<float> codes;  // one map's, reused

  for (int map_index : active) {
    const ImageMap& m = maps.maps[map_index];
    const int w = m.camera.width, h = m.camera.height;
    std::vector<float> threshold(static_cast<size_t>(w) * h);
    codes_of(map_index, codes);
    IBR_CHECK_EQ(codes.size(), threshold.size());
    for (int row = 0; row < h; ++row) {
      for (int col = 0; col < w; ++col) {
        const float c = codes[static_cast<size_t>(row) * w + col];
        float a;
        if (c < 0) {
          a = kInf;  // outside the silhouette: never accepts
        } else if (policy.visual_hull) {
          a = -kInf;
        } else if (c > 0) {
          a = c;
        } else {
          a = policy.invalid_depth_passes ? -kInf : kInf;
        }
        threshold[static_cast<size_t>(row) * w + col] = a;
      }
    }
    const MinPyramid pyramid(std::move(threshold), w, h);

    // Every grid vertex in this map: (u, v) in pixels, z = map camera z.
    const glm::dmat4 cam_from_box = m.cam_from_world * maps.world_from_box;
    for (int k = 0; k < nv; ++k) {
      for (int j = 0; j < nv; ++j) {
        for (int i = 0; i < nv; ++i) {
          const glm::dvec3 q(cam_from_box *
                             glm::dvec4(double(i) / n, double(j) / n, double(k) / n, 1.0));
          glm::dvec3 r(0, 0, q.z);
          if (m.camera.orthographic) {
            r.x = q.x * m.camera.fx + m.camera.cx;
            r.y = q.y * m.camera.fy + m.camera.cy;
          } else if (q.z > 0) {
            r.x = q.x / q.z * m.camera.fx + m.camera.cx;
            r.y = q.y / q.z * m.camera.fy + m.camera.cy;
          } else {
            r.x = r.y = std::nan("");  // behind the camera: no proof below
          }
          uvz[(static_cast<size_t>(k) * nv + j) * nv + i] = r;
        }
      }
    }

    for (int z = 0; z < n; ++z) {
      for (int y = 0; y < n; ++y) {
        for (int x = 0; x < n; ++x) {
          double umin = INFINITY, umax = -INFINITY, vmin = INFINITY, vmax = -INFINITY,
                 zmax = -INFINITY;
          bool ok = true;
          for (int c = 0; c < 8; ++c) {
            const glm::dvec3& r =
                uvz[(static_cast<size_t>(z + (c >> 2)) * nv + y + ((c >> 1) & 1)) * nv + x +
                    (c & 1)];
            ok = ok && std::isfinite(r.x) && std::isfinite(r.y);
            umin = std::min(umin, r.x);
            umax = std::max(umax, r.x);
            vmin = std::min(vmin, r.y);
            vmax = std::max(vmax, r.y);
            zmax = std::max(zmax, r.z);
          }
          if (!ok) continue;
          // Texels the voxel can reach, padded by one on each side.
          const double x0d = std::floor(umin) - 1, x1d = std::floor(umax) + 1;
          const double y0d = std::floor(vmin) - 1, y1d = std::floor(vmax) + 1;
          bool rejected;
          if (x1d < 0 || y1d < 0 || x0d > w - 1 || y0d > h - 1) {
            rejected = !policy.outside_passes;  // wholly outside the image
          } else if (x0d < 0 || y0d < 0 || x1d > w - 1 || y1d > h - 1) {
            if (policy.outside_passes) continue;  // partly outside: unconstrained there
            const int x0 = static_cast<int>(std::max(x0d, 0.0)),
                      x1 = static_cast<int>(std::min(x1d, w - 1.0));
            const int y0 = static_cast<int>(std::max(y0d, 0.0)),
                      y1 = static_cast<int>(std::min(y1d, h - 1.0));
            rejected = zmax + tol < pyramid.Min(x0, x1, y0, y1);
          } else {
            rejected = zmax + tol < pyramid.Min(static_cast<int>(x0d), static_cast<int>(x1d),
                                                static_cast<int>(y0d), static_cast<int>(y1d));
          }
          if (rejected) {
            uint8_t& r = rejections[grid.Index(x, y, z)];
            r = static_cast<uint8_t>(std::min(r + 1, 255));
          }
        }
      }
    }
  }

  grid.distance.assign(rejections.size(), 0);
  const int needed = std::max(policy.rejections_needed, 1);
  for (size_t i = 0; i < rejections.size(); ++i) {
    const bool empty = rejections[i] >= needed;
    grid.distance[i] = empty ? 1 : 0;
    grid.empty_voxels += empty;
  }
  ChessboardDistance(n, grid.distance);
  return grid;
}

}  // namespace ibr
