#include "core/mesh.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/check.h"
#include "core/error.h"

namespace core {

void TriangleMesh::Bounds(glm::vec3& lo, glm::vec3& hi) const {
  lo = glm::vec3(INFINITY);
  hi = glm::vec3(-INFINITY);
  for (const auto& p : positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
}

void TriangleMesh::Validate(const std::string& where) const {
  if (indices.size() % 3 != 0)
    ThrowInputError(where, "index count {} is not a multiple of 3", indices.size());
  if (!normals.empty() && normals.size() != positions.size()) {
    ThrowInputError(where, "{} normals for {} vertices", normals.size(), positions.size());
  }
  if (!uvs.empty() && uvs.size() != positions.size()) {
    ThrowInputError(where, "{} uvs for {} vertices", uvs.size(), positions.size());
  }
  for (uint32_t i : indices) {
    if (i >= positions.size())
      ThrowInputError(where, "index {} out of range ({} vertices)", i, positions.size());
  }
  auto finite = [](auto v) {
    for (int k = 0; k < v.length(); ++k)
      if (!std::isfinite(v[k])) return false;
    return true;
  };
  for (const auto& p : positions)
    if (!finite(p)) ThrowInputError(where, "non-finite vertex position");
  for (const auto& n : normals)
    if (!finite(n)) ThrowInputError(where, "non-finite normal");
  for (const auto& t : uvs)
    if (!finite(t)) ThrowInputError(where, "non-finite uv");
}

void SetAreaWeightedNormals(TriangleMesh& mesh) {
  mesh.normals.assign(mesh.positions.size(), glm::vec3(0));
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const uint32_t a = mesh.indices[3 * t], b = mesh.indices[3 * t + 1],
                   c = mesh.indices[3 * t + 2];
    const glm::vec3 n =
        glm::cross(mesh.positions[b] - mesh.positions[a], mesh.positions[c] - mesh.positions[a]);
    mesh.normals[a] += n;
    mesh.normals[b] += n;
    mesh.normals[c] += n;
  }
  for (auto& n : mesh.normals) {
    const float len = glm::length(n);
    n = len > 1e-30f ? n / len : glm::vec3(0, 0, 1);
  }
}

namespace {
constexpr float kPi = std::numbers::pi_v<float>;

// Quads over a (cols+1) x (rows+1) vertex grid, counter-clockwise when the
// grid's u runs right and v runs up as seen from outside.
void GridIndices(int cols, int rows, std::vector<uint32_t>& indices) {
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < cols; ++i) {
      const uint32_t a = j * (cols + 1) + i, b = a + 1, c = a + (cols + 1), d = c + 1;
      indices.insert(indices.end(), {a, b, d, a, d, c});
    }
  }
}
}  // namespace

TriangleMesh MakeSphere(float radius, int rings, int segments) {
  IBR_CHECK(radius > 0 && rings >= 2 && segments >= 3);
  TriangleMesh mesh;
  for (int j = 0; j <= rings; ++j) {
    const float v = static_cast<float>(j) / rings;
    const float theta = kPi * (v - 0.5f);  // latitude, -pi/2 (south) .. pi/2
    for (int i = 0; i <= segments; ++i) {
      const float u = static_cast<float>(i) / segments;
      const float phi = 2 * kPi * u;
      const glm::vec3 n(std::cos(theta) * std::cos(phi), std::cos(theta) * std::sin(phi),
                        std::sin(theta));
      mesh.positions.push_back(radius * n);
      mesh.normals.push_back(n);
      mesh.uvs.emplace_back(u, v);
    }
  }
  GridIndices(segments, rings, mesh.indices);
  return mesh;
}

TriangleMesh MakeCapsule(float radius, float length, int cap_rings, int stacks, int segments) {
  IBR_CHECK(radius > 0 && length > 0 && cap_rings >= 1 && stacks >= 1 && segments >= 3);
  const float cap_arc = 0.5f * kPi * radius;
  const float total = 2 * cap_arc + length;
  // Profile rows from the south pole: (radial distance, z, normal's z-angle).
  struct Row {
    float r, z, theta, v;
  };
  std::vector<Row> rows;
  for (int j = 0; j <= cap_rings; ++j) {
    const float theta = -0.5f * kPi + 0.5f * kPi * j / cap_rings;  // latitude
    rows.push_back({radius * std::cos(theta), -0.5f * length + radius * std::sin(theta), theta,
                    cap_arc * j / cap_rings / total});
  }
  for (int j = 1; j < stacks; ++j) {
    const float s = static_cast<float>(j) / stacks;
    rows.push_back({radius, length * (s - 0.5f), 0.0f, (cap_arc + s * length) / total});
  }
  for (int j = 0; j <= cap_rings; ++j) {
    const float theta = 0.5f * kPi * j / cap_rings;
    rows.push_back({radius * std::cos(theta), 0.5f * length + radius * std::sin(theta), theta,
                    (cap_arc + length + cap_arc * j / cap_rings) / total});
  }
  rows.front().r = rows.back().r = 0;  // the poles exactly on the axis
  rows.back().v = 1;
  TriangleMesh mesh;
  for (const Row& row : rows) {
    for (int i = 0; i <= segments; ++i) {
      const float u = static_cast<float>(i) / segments;
      const float phi = 2 * kPi * u;
      const glm::vec3 radial(std::cos(phi), std::sin(phi), 0);
      mesh.positions.push_back(row.r * radial + glm::vec3(0, 0, row.z));
      mesh.normals.push_back(std::cos(row.theta) * radial + glm::vec3(0, 0, std::sin(row.theta)));
      mesh.uvs.emplace_back(u, row.v);
    }
  }
  GridIndices(segments, static_cast<int>(rows.size()) - 1, mesh.indices);
  return mesh;
}

TriangleMesh MakeTorus(float major, float minor, int ring_segments, int tube_segments) {
  IBR_CHECK(major > minor && minor > 0 && ring_segments >= 3 && tube_segments >= 3);
  TriangleMesh mesh;
  for (int j = 0; j <= tube_segments; ++j) {
    const float v = static_cast<float>(j) / tube_segments;
    const float psi = 2 * kPi * v;  // around the tube, 0 = outer equator
    for (int i = 0; i <= ring_segments; ++i) {
      const float u = static_cast<float>(i) / ring_segments;
      const float phi = 2 * kPi * u;
      const glm::vec3 radial(std::cos(phi), std::sin(phi), 0);
      const glm::vec3 n = std::cos(psi) * radial + glm::vec3(0, 0, std::sin(psi));
      mesh.positions.push_back(major * radial + minor * n);
      mesh.normals.push_back(n);
      mesh.uvs.emplace_back(u, v);
    }
  }
  GridIndices(ring_segments, tube_segments, mesh.indices);
  return mesh;
}

TriangleMesh MakeBox(glm::vec3 h) {
  TriangleMesh mesh;
  // Each face: normal n, in-plane axes (s, t) with s x t = n.
  const glm::vec3 faces[6][3] = {
      {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
      {{0, 1, 0}, {0, 0, 1}, {1, 0, 0}}, {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
      {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}}, {{0, 0, -1}, {0, 1, 0}, {1, 0, 0}}};
  for (const auto& f : faces) {
    const uint32_t base = static_cast<uint32_t>(mesh.positions.size());
    for (int k = 0; k < 4; ++k) {
      const float a = (k == 1 || k == 3) ? 1.f : -1.f;
      const float b = (k >= 2) ? 1.f : -1.f;
      mesh.positions.push_back(h * (f[0] + a * f[1] + b * f[2]));
      mesh.normals.push_back(f[0]);
      mesh.uvs.emplace_back(0.5f * (a + 1), 0.5f * (b + 1));
    }
    mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 3, base, base + 3, base + 2});
  }
  return mesh;
}

TriangleMesh MakePlane(float half_size, int cells) {
  IBR_CHECK(half_size > 0 && cells >= 1);
  TriangleMesh mesh;
  for (int j = 0; j <= cells; ++j) {
    for (int i = 0; i <= cells; ++i) {
      const glm::vec2 uv(static_cast<float>(i) / cells, static_cast<float>(j) / cells);
      mesh.positions.emplace_back(half_size * (2 * uv.x - 1), half_size * (2 * uv.y - 1), 0);
      mesh.normals.emplace_back(0, 0, 1);
      mesh.uvs.push_back(uv);
    }
  }
  GridIndices(cells, cells, mesh.indices);
  return mesh;
}

}  // namespace core

namespace core {

TriangleMesh MakeCup(float radius, float height, float wall, int segments) {
  IBR_CHECK(radius > wall && height > wall && wall > 0 && segments >= 3);
  // Closed profile in (r, z), walked so that (dz, -dr) is the outward normal.
  const glm::vec2 profile[] = {
      {0, 0},   {radius, 0}, {radius, height}, {radius - wall, height}, {radius - wall, wall},
      {0, wall}};
  TriangleMesh mesh;
  for (int s = 0; s + 1 < 6; ++s) {
    const glm::vec2 p0 = profile[s], p1 = profile[s + 1];
    const glm::vec2 d = glm::normalize(p1 - p0);
    const glm::vec2 n(d.y, -d.x);
    const uint32_t base = static_cast<uint32_t>(mesh.positions.size());
    for (int j = 0; j <= 1; ++j) {
      const glm::vec2 p = j == 0 ? p0 : p1;
      for (int i = 0; i <= segments; ++i) {
        const float u = static_cast<float>(i) / segments;
        const float phi = 2 * std::numbers::pi_v<float> * u;
        const float c = std::cos(phi), sn = std::sin(phi);
        mesh.positions.emplace_back(p.x * c, p.x * sn, p.y);
        mesh.normals.emplace_back(n.x * c, n.x * sn, n.y);
        mesh.uvs.emplace_back(u, (s + j) / 5.0f);
      }
    }
    std::vector<uint32_t> local;
    GridIndices(segments, 1, local);
    for (uint32_t idx : local) mesh.indices.push_back(base + idx);
  }
  return mesh;
}

TriangleMesh MakeMug(float radius, float height, float wall, float handle_radius, float handle_tube,
                     int segments) {
  IBR_CHECK(handle_radius > handle_tube && handle_tube > 0);
  TriangleMesh mesh = MakeCup(radius, height, wall, segments);
  const TriangleMesh handle =
      MakeTorus(handle_radius, handle_tube, std::max(segments / 2, 3), std::max(segments / 8, 3));
  // The tube's innermost point sits a quarter wall outside the cavity (radius
  // - wall), inside the wall: the ring centre is that far plus the ring and
  // tube radii out.
  const glm::vec3 centre(radius - 0.75f * wall + handle_radius + handle_tube, 0, 0.5f * height);
  const uint32_t base = static_cast<uint32_t>(mesh.positions.size());
  // Rotation about x by +90 degrees, (x, y, z) -> (x, -z, y): the torus axis
  // +z becomes -y, so the ring lies in the xz-plane (orientation kept).
  auto rotate = [](const glm::vec3& p) { return glm::vec3(p.x, -p.z, p.y); };
  for (size_t i = 0; i < handle.positions.size(); ++i) {
    mesh.positions.push_back(centre + rotate(handle.positions[i]));
    mesh.normals.push_back(rotate(handle.normals[i]));
    mesh.uvs.push_back(handle.uvs[i]);
  }
  for (uint32_t idx : handle.indices) mesh.indices.push_back(base + idx);
  return mesh;
}

}  // namespace core

namespace core {

TriangleMesh MakeCylinder(float radius, float height, int segments, int stacks) {
  IBR_CHECK(radius > 0 && height > 0 && segments >= 3 && stacks >= 1);
  constexpr float kTwoPi = 2 * std::numbers::pi_v<float>;
  TriangleMesh mesh;
  for (int j = 0; j <= stacks; ++j) {
    const float v = static_cast<float>(j) / stacks;
    for (int i = 0; i <= segments; ++i) {
      const float u = static_cast<float>(i) / segments;
      const glm::vec3 radial(std::cos(kTwoPi * u), std::sin(kTwoPi * u), 0);
      mesh.positions.push_back(radius * radial + glm::vec3(0, 0, height * (v - 0.5f)));
      mesh.normals.push_back(radial);
      mesh.uvs.emplace_back(u, v);
    }
  }
  // u right, v (= +z) up seen from outside: counter-clockwise.
  for (int j = 0; j < stacks; ++j) {
    for (int i = 0; i < segments; ++i) {
      const uint32_t a = j * (segments + 1) + i, b = a + 1, c = a + (segments + 1), d = c + 1;
      mesh.indices.insert(mesh.indices.end(), {a, b, d, a, d, c});
    }
  }
  return mesh;
}

TriangleMesh MakeIrregularVase(float radius, float height, int segments, int stacks,
                               uint32_t seed) {
  IBR_CHECK(radius > 0 && height > 0 && segments >= 3 && stacks >= 1);
  constexpr float kTwoPi = 2 * std::numbers::pi_v<float>;
  // The analytic surface f(u, v): radius profile bulging along the height and
  // lobed around the axis.
  auto surface = [&](glm::vec2 uv) {
    const float phi = kTwoPi * uv.x;
    const float r = radius * (1.0f + 0.25f * std::sin(kTwoPi * 0.75f * uv.y + 0.5f) +
                              0.08f * std::cos(3 * phi + 2.0f * uv.y));
    return glm::vec3(r * std::cos(phi), r * std::sin(phi), height * (uv.y - 0.5f));
  };
  // Deterministic jitter from a small integer hash (no global RNG state).
  auto hash01 = [seed](uint32_t a, uint32_t b) {
    uint32_t h = seed * 0x9E3779B1u ^ (a * 0x85EBCA77u) ^ (b * 0xC2B2AE3Du);
    h ^= h >> 15;
    h *= 0x2C1B3C6Du;
    h ^= h >> 12;
    h *= 0x297A2D39u;
    h ^= h >> 15;
    return static_cast<float>(h & 0xFFFFFF) / static_cast<float>(0x1000000);
  };
  TriangleMesh mesh;
  for (int j = 0; j <= stacks; ++j) {
    for (int i = 0; i <= segments; ++i) {
      // The seam column i = segments repeats column 0 shifted by one in u.
      const int ic = i == segments ? 0 : i;
      float u = static_cast<float>(i) / segments;
      float v = static_cast<float>(j) / stacks;
      if (ic != 0) u += (hash01(ic, j) - 0.5f) * 0.6f / segments;
      if (j != 0 && j != stacks) v += (hash01(ic + 7919u, j) - 0.5f) * 0.6f / stacks;
      const glm::vec2 uv(u, v);
      mesh.uvs.push_back(uv);
      mesh.positions.push_back(surface(uv));
      // Normal from central differences of f: (df/du x df/dv), outward.
      const float e = 1e-3f;
      const glm::vec3 du = surface(uv + glm::vec2(e, 0)) - surface(uv - glm::vec2(e, 0));
      const glm::vec3 dv = surface(uv + glm::vec2(0, e)) - surface(uv - glm::vec2(0, e));
      mesh.normals.push_back(glm::normalize(glm::cross(du, dv)));
    }
  }
  for (int j = 0; j < stacks; ++j) {
    for (int i = 0; i < segments; ++i) {
      const uint32_t a = j * (segments + 1) + i, b = a + 1, c = a + (segments + 1), d = c + 1;
      if (hash01(i + 104729u, j) < 0.5f) {
        mesh.indices.insert(mesh.indices.end(), {a, b, d, a, d, c});
      } else {
        mesh.indices.insert(mesh.indices.end(), {a, b, c, b, d, c});
      }
    }
  }
  return mesh;
}

}  // namespace core
