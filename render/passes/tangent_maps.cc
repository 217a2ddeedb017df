#include "render/passes/tangent_maps.h"

#include <fmt/format.h>

#include <cmath>
#include <cstddef>
#include <map>
#include <set>
#include <tuple>

#include "core/error.h"
#include "core/memory_budget.h"
#include "render/gl/render_target.h"

namespace render {

void TangentMapOptions::Check() const {
  if (size < 2 || size > 8192)
    core::ThrowInputError("TangentMapOptions", "size {} outside 2..8192", size);
  if (!(max_scale > 0) || !std::isfinite(max_scale)) {
    core::ThrowInputError("TangentMapOptions", "max_scale {} must be finite and > 0", max_scale);
  }
  // Over a pole the ray goes on half a period along the other axis.
  if ((pole_u0 || pole_u1) && (wrap_u || !wrap_v))
    core::ThrowInputError("TangentMapOptions", "a pole at u = 0 or 1 needs v periodic, u not");
  if ((pole_v0 || pole_v1) && (wrap_v || !wrap_u))
    core::ThrowInputError("TangentMapOptions", "a pole at v = 0 or 1 needs u periodic, v not");
}

TangentFrames ComputeTangentFrames(const core::TriangleMesh& mesh, float max_scale) {
  mesh.Validate("ComputeTangentFrames");
  if (mesh.normals.empty() || mesh.uvs.empty()) {
    core::ThrowInputError("ComputeTangentFrames", "the mesh needs normals and uvs");
  }
  const size_t n = mesh.positions.size();
  std::vector<glm::dvec3> dpdu(n, glm::dvec3(0)), dpdv(n, glm::dvec3(0));
  std::vector<double> weight(n, 0), len_u(n, 0), len_v(n, 0);
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const uint32_t i[3] = {mesh.indices[3 * t], mesh.indices[3 * t + 1], mesh.indices[3 * t + 2]};
    const glm::dvec3 e1 = glm::dvec3(mesh.positions[i[1]]) - glm::dvec3(mesh.positions[i[0]]);
    const glm::dvec3 e2 = glm::dvec3(mesh.positions[i[2]]) - glm::dvec3(mesh.positions[i[0]]);
    const glm::dvec2 w1 = glm::dvec2(mesh.uvs[i[1]]) - glm::dvec2(mesh.uvs[i[0]]);
    const glm::dvec2 w2 = glm::dvec2(mesh.uvs[i[2]]) - glm::dvec2(mesh.uvs[i[0]]);
    const double det = w1.x * w2.y - w2.x * w1.y;  // twice the signed UV area
    if (!(std::abs(det) > 1e-14)) continue;        // zero-area UV triangle: no parameterisation
    // Solve e = dP/du * du + dP/dv * dv for both edges.
    const glm::dvec3 pu = (e1 * w2.y - e2 * w1.y) / det;
    const glm::dvec3 pv = (e2 * w1.x - e1 * w2.x) / det;
    const double area = 0.5 * std::abs(det);
    for (uint32_t k : i) {
      dpdu[k] += area * pu;
      dpdv[k] += area * pv;
      len_u[k] += area * glm::length(pu);
      len_v[k] += area * glm::length(pv);
      weight[k] += area;
    }
  }
  // Seam duplicates (same position, uv differing by whole periods, e.g.
  // u = 0 and u = 1 on a torus) are one surface point: pool their sums so
  // the frame there sees the triangles on both sides of the seam.
  {
    std::map<std::tuple<float, float, float, float, float>, std::vector<size_t>> groups;
    for (size_t k = 0; k < n; ++k) {
      const glm::vec3& p = mesh.positions[k];
      const glm::vec2 f = mesh.uvs[k] - glm::floor(mesh.uvs[k] + 1e-6f);
      // Positions to 1e-5 scene units: analytic seams differ by rounding
      // (sin(2 pi) != 0 in float).
      groups[{std::round(p.x * 1e5f), std::round(p.y * 1e5f), std::round(p.z * 1e5f),
              std::round(f.x * 1e5f), std::round(f.y * 1e5f)}]
          .push_back(k);
    }
    for (const auto& [key, members] : groups) {
      if (members.size() < 2) continue;
      glm::dvec3 su(0), sv(0);
      double sw = 0, slu = 0, slv = 0;
      for (size_t k : members) {
        su += dpdu[k];
        sv += dpdv[k];
        sw += weight[k];
        slu += len_u[k];
        slv += len_v[k];
      }
      for (size_t k : members) {
        dpdu[k] = su;
        dpdv[k] = sv;
        weight[k] = sw;
        len_u[k] = slu;
        len_v[k] = slv;
      }
    }
  }
  TangentFrames frames;
  frames.tangents.resize(n);
  frames.s_tangent.resize(n);
  frames.s_binormal.resize(n);
  frames.handedness.resize(n);
  for (size_t k = 0; k < n; ++k) {
    const glm::dvec3 normal = glm::normalize(glm::dvec3(mesh.normals[k]));
    glm::dvec3 t = dpdu[k] - glm::dot(dpdu[k], normal) * normal;
    if (glm::length(t) < 1e-12 * std::max(1.0, weight[k])) {
      // Degenerate (pole, isolated vertex): any unit vector orthogonal to N;
      // prefer the direction of dP/dv rotated into the tangent plane.
      glm::dvec3 b = dpdv[k] - glm::dot(dpdv[k], normal) * normal;
      if (glm::length(b) > 1e-12) {
        t = glm::cross(b, normal);
      } else {
        const glm::dvec3 a = std::abs(normal.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
        t = glm::cross(normal, a);
      }
    }
    t = glm::normalize(t);
    frames.tangents[k] = glm::vec3(t);
    frames.handedness[k] = glm::dot(glm::cross(normal, t), dpdv[k]) < 0 ? -1.0f : 1.0f;
    auto scale = [&](double len_sum) {
      if (!(len_sum > 0) || weight[k] <= 0) return max_scale;
      return static_cast<float>(std::min<double>(max_scale, weight[k] / len_sum));
    };
    frames.s_tangent[k] = scale(len_u[k]);
    frames.s_binormal[k] = scale(len_v[k]);
  }
  return frames;
}

void DetectPeriodicAxes(const core::TriangleMesh& mesh, bool& wrap_u, bool& wrap_v) {
  auto periodic = [&](int axis) {
    std::set<std::tuple<long, long, long, long>> far_side;
    for (size_t k = 0; k < mesh.uvs.size(); ++k) {
      if (std::abs(mesh.uvs[k][axis] - 1.0f) > 1e-6f) continue;
      const glm::vec3& p = mesh.positions[k];
      far_side.insert({std::lround(p.x * 1e4f), std::lround(p.y * 1e4f), std::lround(p.z * 1e4f),
                       std::lround(mesh.uvs[k][1 - axis] * 1e5f)});
    }
    int seam = 0;
    for (size_t k = 0; k < mesh.uvs.size(); ++k) {
      if (std::abs(mesh.uvs[k][axis]) > 1e-6f) continue;
      const glm::vec3& p = mesh.positions[k];
      if (!far_side.count({std::lround(p.x * 1e4f), std::lround(p.y * 1e4f),
                           std::lround(p.z * 1e4f), std::lround(mesh.uvs[k][1 - axis] * 1e5f)})) {
        return false;
      }
      ++seam;
    }
    return seam > 0;
  };
  wrap_u = !mesh.uvs.empty() && periodic(0);
  wrap_v = !mesh.uvs.empty() && periodic(1);
}

void DetectChart(const core::TriangleMesh& mesh, TangentMapOptions& options) {
  DetectPeriodicAxes(mesh, options.wrap_u, options.wrap_v);
  // Edge `side` (0 or 1) of coordinate `axis` is a pole when its vertices
  // are one point and spread along the other coordinate.
  auto pole = [&](int axis, float side) {
    bool any = false;
    glm::vec3 first(0);
    float lo = 1e30f, hi = -1e30f;
    for (size_t k = 0; k < mesh.uvs.size(); ++k) {
      if (std::abs(mesh.uvs[k][axis] - side) > 1e-6f) continue;
      if (!any) first = mesh.positions[k];
      any = true;
      if (glm::length(mesh.positions[k] - first) > 1e-4f) return false;
      lo = std::min(lo, mesh.uvs[k][1 - axis]);
      hi = std::max(hi, mesh.uvs[k][1 - axis]);
    }
    return any && hi - lo >= 0.5f;
  };
  options.pole_u0 = options.pole_u1 = options.pole_v0 = options.pole_v1 = false;
  if (options.wrap_v && !options.wrap_u) {
    options.pole_u0 = pole(0, 0.0f);
    options.pole_u1 = pole(0, 1.0f);
  }
  if (options.wrap_u && !options.wrap_v) {
    options.pole_v0 = pole(1, 0.0f);
    options.pole_v1 = pole(1, 1.0f);
  }
}

namespace {
struct MapVertex {
  glm::vec2 uv;
  glm::vec3 normal;
  glm::vec4 tangent;  // xyz, w = handedness * S_tangent
  float s_binormal;
};
}  // namespace

TangentMaps RenderTangentMaps(ProgramCache& programs, const core::TriangleMesh& mesh,
                              const TangentMapOptions& options) {
  options.Check();
  return RenderTangentMaps(programs, mesh, options, ComputeTangentFrames(mesh, options.max_scale));
}

TangentMaps RenderTangentMaps(ProgramCache& programs, const core::TriangleMesh& mesh,
                              const TangentMapOptions& options, const TangentFrames& frames) {
  options.Check();
  IBR_CHECK(frames.tangents.size() == mesh.positions.size());
  // Two RGBA32F maps in the driver's memory (llvmpipe: system memory).
  core::CheckMemory(2ull * options.size * options.size * 4 * sizeof(float), "RenderTangentMaps",
                    fmt::format("the two {}x{} tangent-space maps", options.size, options.size));
  std::vector<MapVertex> vertices(mesh.positions.size());
  for (size_t k = 0; k < vertices.size(); ++k) {
    vertices[k] = {mesh.uvs[k], glm::normalize(mesh.normals[k]),
                   glm::vec4(frames.tangents[k], frames.handedness[k] * frames.s_tangent[k]),
                   frames.s_binormal[k]};
  }
  IBR_CHECK(!vertices.empty() && !mesh.indices.empty());
  Buffer vbo = Buffer::CreateWithData(vertices.data(),
                                      static_cast<GLsizeiptr>(vertices.size() * sizeof(MapVertex)));
  Buffer ibo = Buffer::CreateWithData(
      mesh.indices.data(), static_cast<GLsizeiptr>(mesh.indices.size() * sizeof(uint32_t)));
  VertexArray vao = VertexArray::Create();
  glVertexArrayVertexBuffer(vao.id(), 0, vbo.id(), 0, sizeof(MapVertex));
  glVertexArrayElementBuffer(vao.id(), ibo.id());
  // The attribute convention (ARCHITECTURE.md, "Conventions"): 1 normal, 2 uv; 3-4 the frame.
  const GLuint locations[] = {2, 1, 3, 4};
  const GLint sizes[] = {2, 3, 4, 1};
  const GLuint offsets[] = {offsetof(MapVertex, uv), offsetof(MapVertex, normal),
                            offsetof(MapVertex, tangent), offsetof(MapVertex, s_binormal)};
  for (int k = 0; k < 4; ++k) {
    glEnableVertexArrayAttrib(vao.id(), locations[k]);
    glVertexArrayAttribFormat(vao.id(), locations[k], sizes[k], GL_FLOAT, GL_FALSE, offsets[k]);
    glVertexArrayAttribBinding(vao.id(), locations[k], 0);
  }

  // Rendering into the maps' own textures: an FBO around two RGBA32F textures.
  TangentMaps maps;
  maps.options = options;
  maps.normal_map = Texture::Create2D(GL_RGBA32F, options.size, options.size);
  maps.tangent_map = Texture::Create2D(GL_RGBA32F, options.size, options.size);
  Framebuffer fbo = Framebuffer::Create();
  glNamedFramebufferTexture(fbo.id(), GL_COLOR_ATTACHMENT0, maps.normal_map.id(), 0);
  glNamedFramebufferTexture(fbo.id(), GL_COLOR_ATTACHMENT1, maps.tangent_map.id(), 0);
  const GLenum buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  glNamedFramebufferDrawBuffers(fbo.id(), 2, buffers);
  IBR_CHECK_EQ(glCheckNamedFramebufferStatus(fbo.id(), GL_DRAW_FRAMEBUFFER),
               GLenum(GL_FRAMEBUFFER_COMPLETE));
  const float zero[4] = {0, 0, 0, 0};
  glClearNamedFramebufferfv(fbo.id(), GL_COLOR, 0, zero);
  glClearNamedFramebufferfv(fbo.id(), GL_COLOR, 1, zero);

  const Program& program = programs.Get(
      {.vertex = "passes/tangent_maps.vert.glsl", .fragment = "passes/tangent_maps.frag.glsl"});
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo.id());
  glViewport(0, 0, options.size, options.size);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_STENCIL_TEST);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  program.Use();
  glBindVertexArray(vao.id());
  glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(mesh.indices.size()), GL_UNSIGNED_INT, nullptr);
  glBindVertexArray(0);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);

  for (const Texture* tex : {&maps.normal_map, &maps.tangent_map}) {
    glTextureParameteri(tex->id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(tex->id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(tex->id(), GL_TEXTURE_WRAP_S,
                        options.wrap_u ? GL_REPEAT : GL_CLAMP_TO_EDGE);
    glTextureParameteri(tex->id(), GL_TEXTURE_WRAP_T,
                        options.wrap_v ? GL_REPEAT : GL_CLAMP_TO_EDGE);
  }
  return maps;
}

}  // namespace render
