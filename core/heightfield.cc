#include "core/heightfield.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "core/error.h"
#include "core/memory_budget.h"

namespace core {

namespace {
// Value noise on a periodic lattice of `cells` cells, smooth-step interpolated.
float PeriodicValueNoise(const std::vector<float>& lattice, int cells, float x, float y) {
  const float fx = std::floor(x), fy = std::floor(y);
  const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  const float tx = x - fx, ty = y - fy;
  const float sx = tx * tx * (3 - 2 * tx), sy = ty * ty * (3 - 2 * ty);
  auto at = [&](int i, int j) {
    i = ((i % cells) + cells) % cells;
    j = ((j % cells) + cells) % cells;
    return lattice[static_cast<size_t>(j) * cells + i];
  };
  const float a = at(x0, y0) + sx * (at(x0 + 1, y0) - at(x0, y0));
  const float b = at(x0, y0 + 1) + sx * (at(x0 + 1, y0 + 1) - at(x0, y0 + 1));
  return a + sy * (b - a);
}
}  // namespace

HeightPattern HeightPatternFromName(const std::string& name) {
  return EnumFromName(kHeightPatternNames, name, "HeightPatternFromName", "height pattern");
}

std::string HeightPatternName(HeightPattern pattern) {
  return std::string(EnumToName(kHeightPatternNames, pattern));
}

void HeightMapOptions::Check() const {
  if (size < 1 || size > 8192) ThrowInputError("HeightMapOptions", "size {} outside 1..8192", size);
  if (!(level >= 0.0f && level <= 1.0f)) {
    ThrowInputError("HeightMapOptions", "level {} outside [0, 1]", level);
  }
}

ImageF MakeHeightMap(const HeightMapOptions& options) {
  options.Check();
  const int n = options.size;
  ImageF image(n, n, 1, 0.0f);
  constexpr float kPi = std::numbers::pi_v<float>;
  std::mt19937 rng(options.seed);
  std::vector<float> lattices[4];
  if (options.pattern == HeightPattern::kNoise) {
    for (int o = 0; o < 4; ++o) {
      const int cells = 4 << o;
      lattices[o].resize(static_cast<size_t>(cells) * cells);
      for (float& v : lattices[o]) v = std::uniform_real_distribution<float>(0, 1)(rng);
    }
  }
  std::vector<glm::ivec2> spikes;
  if (options.pattern == HeightPattern::kSpikes) {
    const int count = std::max(1, n * n / 256);
    for (int i = 0; i < count; ++i) spikes.emplace_back(rng() % n, rng() % n);
  }
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const float u = (x + 0.5f) / n, v = (y + 0.5f) / n;
      float h = 0;
      switch (options.pattern) {
        case HeightPattern::kConstant:
          h = 1.0f;
          break;
        case HeightPattern::kBumps:
          // 4 x 4 bumps per tile: (1 - cos)/2 profile in both directions.
          h = 0.25f * (1 - std::cos(8 * kPi * u)) * (1 - std::cos(8 * kPi * v));
          break;
        case HeightPattern::kNoise: {
          float amplitude = 0.5f, sum = 0, norm = 0;
          for (int o = 0; o < 4; ++o) {
            const int cells = 4 << o;
            sum += amplitude * PeriodicValueNoise(lattices[o], cells, u * cells, v * cells);
            norm += amplitude;
            amplitude *= 0.5f;
          }
          h = sum / norm;
          break;
        }
        case HeightPattern::kBricks: {
          // 4 rows of 2 bricks per tile, alternate rows offset by half a brick;
          // mortar 1/16 of a brick height wide at height 0.2.
          const float row = v * 4;
          const int row_index = static_cast<int>(std::floor(row));
          const float col = u * 2 + (row_index % 2 ? 0.5f : 0.0f);
          const float fr = row - std::floor(row), fc = col - std::floor(col);
          const float mortar = 1.0f / 16;
          const bool in_mortar = fr < mortar || fc < mortar * 0.5f;
          h = in_mortar ? 0.2f : 1.0f;
          break;
        }
        case HeightPattern::kSteps:
          h = std::floor(u * 4) / 3.0f;  // 0, 1/3, 2/3, 1
          break;
        case HeightPattern::kSpikes:
          h = 0.05f;
          break;
      }
      image.at(x, y) = options.level * std::clamp(h, 0.0f, 1.0f);
    }
  }
  for (const glm::ivec2& s : spikes) {
    // A plus-shaped spike: centre at full height, 4-neighbours at 0.6.
    image.at(s.x, s.y) = options.level;
    const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
    for (int k = 0; k < 4; ++k) {
      float& t = image.at((s.x + dx[k] + n) % n, (s.y + dy[k] + n) % n);
      t = std::max(t, 0.6f * options.level);
    }
  }
  return image;
}

float SampleHeightBilinear(const ImageF& height, glm::vec2 uv) {
  const int w = height.width(), h = height.height();
  const float x = uv.x * w - 0.5f, y = uv.y * h - 0.5f;
  const float fx = std::floor(x), fy = std::floor(y);
  const float tx = x - fx, ty = y - fy;
  auto at = [&](int i, int j) {
    i = ((i % w) + w) % w;
    j = ((j % h) + h) % h;
    return height.at(i, j);
  };
  const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  const float a = at(x0, y0) * (1 - tx) + at(x0 + 1, y0) * tx;
  const float b = at(x0, y0 + 1) * (1 - tx) + at(x0 + 1, y0 + 1) * tx;
  return a * (1 - ty) + b * ty;
}

float SampleHeightNearest(const ImageF& height, glm::vec2 uv) {
  const int w = height.width(), h = height.height();
  int i = static_cast<int>(std::floor(uv.x * w)), j = static_cast<int>(std::floor(uv.y * h));
  i = ((i % w) + w) % w;
  j = ((j % h) + h) % h;
  return height.at(i, j);
}

void DisplacedMeshOptions::Check() const {
  if (!std::isfinite(max_displacement) || max_displacement < 0) {
    ThrowInputError("DisplacedMeshOptions", "max_displacement {} must be finite and >= 0",
                    max_displacement);
  }
  if (!std::isfinite(tiling) || tiling <= 0 || tiling > 1024) {
    ThrowInputError("DisplacedMeshOptions", "tiling {} outside (0, 1024]", tiling);
  }
  if (subdivisions < 1 || subdivisions > 1024) {
    ThrowInputError("DisplacedMeshOptions", "subdivisions {} outside 1..1024", subdivisions);
  }
}

TriangleMesh TessellateDisplaced(const TriangleMesh& base, const ImageF& height,
                                 const DisplacedMeshOptions& options) {
  options.Check();
  base.Validate("TessellateDisplaced");
  if (base.normals.empty() || base.uvs.empty()) {
    ThrowInputError("TessellateDisplaced", "the base mesh needs normals and uvs");
  }
  if (height.empty() || height.channels() != 1) {
    ThrowInputError("TessellateDisplaced", "height map must be a non-empty 1-channel image");
  }
  const int s = options.subdivisions;
  const size_t per_triangle = static_cast<size_t>(s + 1) * (s + 2) / 2;
  // Position, normal and uv per vertex; three 32-bit indices per triangle.
  const std::uint64_t vertices = base.triangle_count() * per_triangle;
  const std::uint64_t triangles = base.triangle_count() * static_cast<std::uint64_t>(s) * s;
  if (vertices > 0xffffffffull) {
    ThrowInputError("TessellateDisplaced", "{} vertices exceed 32-bit indices", vertices);
  }
  CheckMemory(vertices * (2 * sizeof(glm::vec3) + sizeof(glm::vec2)) + triangles * 12,
              "TessellateDisplaced",
              fmt::format("the tessellation of {} triangles at {} subdivisions per edge ({} "
                          "triangles)",
                          base.triangle_count(), s, triangles));
  TriangleMesh out;
  out.positions.reserve(base.triangle_count() * per_triangle);
  for (size_t t = 0; t < base.triangle_count(); ++t) {
    const uint32_t ia = base.indices[3 * t], ib = base.indices[3 * t + 1],
                   ic = base.indices[3 * t + 2];
    const uint32_t first = static_cast<uint32_t>(out.positions.size());
    // Vertex (i, j), i + j <= s, at barycentric (1 - (i+j)/s, i/s, j/s).
    auto index = [&](int i, int j) {
      // Row j holds s + 1 - j vertices; rows before it hold sum_{r<j} (s + 1 - r).
      return first + static_cast<uint32_t>(j * (s + 1) - j * (j - 1) / 2 + i);
    };
    for (int j = 0; j <= s; ++j) {
      for (int i = 0; i + j <= s; ++i) {
        const float b1 = static_cast<float>(i) / s, b2 = static_cast<float>(j) / s,
                    b0 = 1 - b1 - b2;
        const glm::vec3 p =
            b0 * base.positions[ia] + b1 * base.positions[ib] + b2 * base.positions[ic];
        glm::vec3 n = b0 * base.normals[ia] + b1 * base.normals[ib] + b2 * base.normals[ic];
        const float len = glm::length(n);
        n = len > 1e-20f ? n / len : glm::vec3(0);
        const glm::vec2 uv = b0 * base.uvs[ia] + b1 * base.uvs[ib] + b2 * base.uvs[ic];
        const glm::vec2 st = uv * options.tiling;
        const float hgt =
            options.bilinear ? SampleHeightBilinear(height, st) : SampleHeightNearest(height, st);
        out.positions.push_back(p + hgt * options.max_displacement * n);
        out.uvs.push_back(uv);
      }
    }
    for (int j = 0; j < s; ++j) {
      for (int i = 0; i + j < s; ++i) {
        out.indices.insert(out.indices.end(), {index(i, j), index(i + 1, j), index(i, j + 1)});
        if (i + j + 1 < s) {
          out.indices.insert(out.indices.end(),
                             {index(i + 1, j), index(i + 1, j + 1), index(i, j + 1)});
        }
      }
    }
  }
  // Area-weighted vertex normals of the displaced surface. Vertices on shared
  // base edges are duplicated per triangle, so normals there come from one
  // side only: fine for shading a reference, not used for geometry.
  SetAreaWeightedNormals(out);
  return out;
}

}  // namespace core
