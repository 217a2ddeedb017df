#include "verify/reference.h"

#include "core/check.h"

// This file mirrors GLSL `precise` arithmetic; ibr/CMakeLists.txt compiles the
// library with -ffp-contract=off so no multiply-add is fused here either.

namespace ibr {

ReferenceVariant ReferenceVariant::From(const DepthObjectOptions& options) {
  ReferenceVariant v;
  v.visual_hull = options.method == Method::kVisualHull;
  v.outside_passes = options.outside == OutsidePolicy::kPass;
  v.invalid_depth_passes = options.invalid_depth == InvalidDepthPolicy::kNoConstraint;
  return v;
}

namespace {

float Div(float a, float b, const ReferenceDivision* division, ReferenceDivision::Site site) {
  return division == nullptr ? a / b : division->Divide(a, b, site);
}

}  // namespace

glm::vec3 ReferenceViewPointOnPlane(const FrameParams& f, glm::vec2 uv, glm::vec4 plane,
                                    const ReferenceDivision* division) {
  const glm::vec4 r = f.view_ray;
  if (f.view_orthographic) {
    const float ox = uv.x * r.x + r.z;
    const float oy = uv.y * r.y + r.w;
    const float s = plane.w - (plane.x * ox + plane.y * oy);
    const float z = Div(s, plane.z, division, ReferenceDivision::kViewPoint);
    return {ox, oy, z};
  }
  const float dx = uv.x * r.x + r.z;
  const float dy = uv.y * r.y + r.w;
  const float den = (plane.x * dx + plane.y * dy) + plane.z;
  const float t = Div(plane.w, den, division, ReferenceDivision::kViewPoint);
  return {t * dx, t * dy, t};
}

bool ReferenceMapLookup(const MapRecord& m, glm::vec3 p, glm::vec3& q, glm::ivec3& texel,
                        const ReferenceDivision* division) {
  for (int c = 0; c < 3; ++c) {
    const float a = m.m0[c] * p.x;
    const float b = m.m1[c] * p.y;
    const float d = m.m2[c] * p.z;
    q[c] = ((a + b) + d) + m.m3[c];
  }
  texel = glm::ivec3(-1);
  float u, v;
  bool in_front;
  if (m.info.z == 1) {
    u = q.x * m.proj.x + m.proj.z;
    v = q.y * m.proj.y + m.proj.w;
    in_front = true;
  } else {
    u = Div(q.x, q.z, division, ReferenceDivision::kMapU) * m.proj.x + m.proj.z;
    v = Div(q.y, q.z, division, ReferenceDivision::kMapV) * m.proj.y + m.proj.w;
    in_front = q.z > 0.0f;
  }
  if (!(in_front && u >= 0.0f && u < static_cast<float>(m.info.x) && v >= 0.0f &&
        v < static_cast<float>(m.info.y))) {
    return false;
  }
  texel = glm::ivec3(static_cast<int>(u), static_cast<int>(v), m.info.w);
  return true;
}

bool ReferenceMapAccepts(const MapTables& t, const MapRecord& m, const ReferenceVariant& variant,
                         glm::vec3 p, glm::ivec3& texel, bool* tie,
                         const ReferenceDivision* division) {
  glm::vec3 q;
  if (!ReferenceMapLookup(m, p, q, texel, division)) return variant.outside_passes;
  const float d = t.depth[t.Index(texel.z, texel.x, texel.y)];
  if (d < 0.0f) return false;  // outside the silhouette
  if (variant.visual_hull) return true;
  if (d > 0.0f) {
    if (tie != nullptr && q.z == d) *tie = true;
    return q.z >= d;
  }
  return variant.invalid_depth_passes;
}

ReferenceBuffers RenderReference(const FrameParams& f, const MapTables& tables,
                                 const ReferenceVariant& variant,
                                 const std::vector<core::Image8>& coverage) {
  IBR_CHECK_EQ(coverage.size(), f.stack.slices.size());
  ReferenceBuffers out;
  out.stencil = core::Image8(f.width, f.height, 1, 0);
  out.color = core::ImageF(f.width, f.height, 4, 0.0f);
  out.depth = core::ImageF(f.width, f.height, 2, 0.0f);
  const int n = static_cast<int>(f.active.size());
  const int num_slices = static_cast<int>(coverage.size());
  for (int s = 0; s < num_slices; ++s) {
    const core::Image8& cov = coverage[s];
    for (int row = 0; row < f.height; ++row) {
      // gl_FragCoord: window row = height - 1 - row, centre + 0.5; the shader
      // computes v = height - gl_FragCoord.y, which is row + 0.5 exactly.
      const float frag_y = static_cast<float>(f.height - 1 - row) + 0.5f;
      const float v = f.view_height - frag_y;
      for (int col = 0; col < f.width; ++col) {
        const int times = cov.at(col, row);
        if (times == 0) continue;
        const glm::vec2 uv(static_cast<float>(col) + 0.5f, v);
        const glm::vec3 p = ReferenceViewPointOnPlane(f, uv, f.planes[s]);
        uint8_t& st = out.stencil.at(col, row);
        const uint8_t st_before = st;
        float* color = &out.color.at(col, row, 0);
        float* depth = &out.depth.at(col, row, 0);
        // Step 2(a): the map loop.
        for (int j = 0; j < n; ++j) {
          const MapRecord& m = f.maps[f.active[j]];
          for (int rep = 0; rep < times; ++rep) {
            const bool stencil_passes = f.robust ? (st & 0x80) == 0 : st == j;
            if (!stencil_passes) continue;  // the shader result is discarded anyway
            ++out.fragments;
            glm::ivec3 texel;
            bool tie = false;
            if (!ReferenceMapAccepts(tables, m, variant, p, texel, &tie)) continue;
            if (tie) ++out.ties;
            st = f.robust ? static_cast<uint8_t>((st & 0x80) | (((st & 0x7F) + 1) & 0x7F))
                          : static_cast<uint8_t>(std::min(st + 1, 255));
            float o[4] = {0, 0, 0, 0};
            if (texel.x >= 0 && m.extra.x > 0.0f) {
              const size_t ti = tables.Index(texel.z, texel.x, texel.y) * 4;
              for (int c = 0; c < 4; ++c) {
                const float cc = static_cast<float>(tables.color[ti + c]) * f.inv255;
                o[c] = cc * m.extra.x;
              }
            }
            for (int c = 0; c < 4; ++c) color[c] = color[c] + o[c];  // blend ONE, ONE
            depth[0] = p.z;
            depth[1] = 1.0f;
          }
        }
        // Steps (c)-(f).
        bool clear;
        if (!f.robust) {
          clear = st != n;
        } else {
          clear = f.required > st;  // finished pixels (bit 7) never qualify
        }
        if (clear) {
          st = 0;
          for (int c = 0; c < 4; ++c) color[c] = 0;
          depth[0] = depth[1] = 0;
        } else if (f.robust && (st & 0x80) == 0 && (st & 0x7F) >= f.required) {
          st = static_cast<uint8_t>(st | 0x80);
          if (s == num_slices - 1) ++out.finished_on_last_slice;
        }
        if (!f.robust && !clear && s == num_slices - 1 && st_before != n)
          ++out.finished_on_last_slice;
      }
    }
  }
  return out;
}

}  // namespace ibr
