#include "core/mesh.h"

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
  if (indices.size() % 3 != 0) ThrowInputError(where, "index count {} is not a multiple of 3", indices.size());
  if (!normals.empty() && normals.size() != positions.size()) {
    ThrowInputError(where, "{} normals for {} vertices", normals.size(), positions.size());
  }
  if (!uvs.empty() && uvs.size() != positions.size()) {
    ThrowInputError(where, "{} uvs for {} vertices", uvs.size(), positions.size());
  }
  for (uint32_t i : indices) {
    if (i >= positions.size()) ThrowInputError(where, "index {} out of range ({} vertices)", i, positions.size());
  }
  auto finite = [](auto v) {
    for (int k = 0; k < v.length(); ++k) if (!std::isfinite(v[k])) return false;
    return true;
  };
  for (const auto& p : positions) if (!finite(p)) ThrowInputError(where, "non-finite vertex position");
  for (const auto& n : normals) if (!finite(n)) ThrowInputError(where, "non-finite normal");
  for (const auto& t : uvs) if (!finite(t)) ThrowInputError(where, "non-finite uv");
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
      const glm::vec3 n(std::cos(theta) * std::cos(phi), std::cos(theta) * std::sin(phi), std::sin(theta));
      mesh.positions.push_back(radius * n);
      mesh.normals.push_back(n);
      mesh.uvs.emplace_back(u, v);
    }
  }
  GridIndices(segments, rings, mesh.indices);
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
      {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}},  {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
      {{0, 1, 0}, {0, 0, 1}, {1, 0, 0}},  {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
      {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}},  {{0, 0, -1}, {0, 1, 0}, {1, 0, 0}}};
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
