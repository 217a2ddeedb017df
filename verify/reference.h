// A CPU reference of the depth-object / visual-hull stencil algorithm
// (Kautz-Seidel 2001, sec. 4.1, steps 1-2(a)-(f)) that evaluates the same
// FrameParams, the same texels (MapTables) and the same float operations as
// shaders/passes/depth_object_core.glsl, so its stencil, colour and depth buffers
// must equal the GPU's bit for bit. The one input it takes from the GPU is
// rasterisation coverage: which pixels each slice polygon covers
// (DepthObjectRenderer::SliceCoverage).
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "core/image.h"
#include "ibr/depth_object.h"

namespace ibr {

// The shader variant the reference mirrors.
struct ReferenceVariant {
  bool visual_hull = false;
  bool outside_passes = true;
  bool invalid_depth_passes = false;
  static ReferenceVariant From(const DepthObjectOptions& options);
};

// The divisions of the mirrored functions. GLSL promises 2.5 ULP for
// division, not correct rounding: `ibr verify` (verify/verify.h) replays a
// decision with other admissible quotients through this hook. nullptr (the
// default) = the correctly rounded a / b.
class ReferenceDivision {
 public:
  // Where a division sits: the view point on a slice plane, a pinhole map's u and v.
  enum Site { kViewPoint = 0, kMapU = 1, kMapV = 2 };
  virtual ~ReferenceDivision() = default;
  virtual float Divide(float a, float b, Site site) const = 0;
};

// Mirrors of the GLSL functions, operation for operation.
glm::vec3 ReferenceViewPointOnPlane(const FrameParams& frame, glm::vec2 uv, glm::vec4 plane,
                                    const ReferenceDivision* division = nullptr);
bool ReferenceMapLookup(const MapRecord& map, glm::vec3 p, glm::vec3& q, glm::ivec3& texel,
                        const ReferenceDivision* division = nullptr);
// `tie` is set when the decision was an exact equality q.z == depth.
bool ReferenceMapAccepts(const MapTables& tables, const MapRecord& map,
                         const ReferenceVariant& variant, glm::vec3 p, glm::ivec3& texel,
                         bool* tie = nullptr, const ReferenceDivision* division = nullptr);

struct ReferenceBuffers {
  core::Image8 stencil;                // 1 channel, row 0 on top
  core::ImageF color;                  // 4 channels RGBA32F accumulation
  core::ImageF depth;                  // 2 channels (camera z, covered)
  int64_t fragments = 0;               // map-pass fragments evaluated
  int64_t ties = 0;                    // decisions where camera z == map depth exactly
  int64_t finished_on_last_slice = 0;  // pixels whose count reached N on the last slice
};

// `coverage[s]` (from the GPU) says how often slice s's polygon covers each
// pixel (row 0 on top).
ReferenceBuffers RenderReference(const FrameParams& frame, const MapTables& tables,
                                 const ReferenceVariant& variant,
                                 const std::vector<core::Image8>& coverage);

}  // namespace ibr
