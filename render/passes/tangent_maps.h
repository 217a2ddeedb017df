// Tangent-space maps of a base mesh (Chen-Chang, sec. 3.1, Algorithm 1): the
// mesh rendered in UV space into a normal map N (xyz = unit normal, w =
// S_binormal) and a tangent map T (xyz = unit tangent, w = +-S_tangent, the
// sign carrying the frame's handedness), so a ray marching in texture space
// can look up the tangent frame at ANY uv, also outside the triangle it
// entered through (sec. 3.1, last paragraph).
//
// Scale factors: S_tangent = du per unit of object-space length along T and
// S_binormal = dv per unit length along B (texture units per scene unit),
// from each triangle's ratio of UV-space to object-space edge lengths, i.e.
// the inverse lengths of its dP/du and dP/dv; without them the texture swims.
// NCS maps a view direction V to the texture-space step
// (S_t T.V, S_b B.V, N.V / max_displacement) (Algorithm 2, line 4).
#pragma once

#include <glm/glm.hpp>
#include <vector>

#include "core/mesh.h"
#include "render/gl/handles.h"
#include "render/gl/shader_program.h"

namespace render {

// Per-vertex tangent frames on the CPU (the "vertex colours" of Algorithm 1).
struct TangentFrames {
  std::vector<glm::vec3> tangents;  // unit, orthogonal to the vertex normal
  std::vector<float> s_tangent;     // > 0, texture units per scene unit along T
  std::vector<float> s_binormal;    // > 0, along B
  std::vector<float> handedness;    // +1 when cross(N, T) points along dP/dv, else -1
};

// Each triangle's dP/du, dP/dv (from its edges in object and UV space) is
// accumulated on its vertices weighted by the triangle's UV area; triangles
// with zero UV area carry no parameterisation and are skipped. Where the
// frame degenerates (sphere poles: dP/du = 0) the tangent is any unit vector
// orthogonal to N and the scale factor is clamped to `max_scale`.
TangentFrames ComputeTangentFrames(const core::TriangleMesh& mesh, float max_scale);

struct TangentMapOptions {
  int size = 512;       // texels per side of both maps (the paper uses 512)
  bool wrap_u = false;  // the parameterisation is periodic in u (torus, sphere, cylinder)
  bool wrap_v = false;  // periodic in v (torus)
  // A chart edge that is a pole: all its vertices coincide (UV sphere,
  // capsule: v = 0 and v = 1, with u periodic). A ray marching over it goes
  // on over the pole, on the far side of the chart (u + 1/2); a chart edge
  // that is neither periodic nor a pole is a border, and a ray leaving
  // through it has left the surface.
  bool pole_u0 = false, pole_u1 = false;  // u = 0, u = 1 (needs wrap_v)
  bool pole_v0 = false, pole_v1 = false;  // v = 0, v = 1 (needs wrap_u)
  float max_scale =
      1.0e4f;  // clamp for S_t / S_b at degenerate frames, texture units per scene unit
  void Check() const;
};

// RGBA32F maps, LINEAR filtered, REPEAT on wrapping axes, CLAMP_TO_EDGE otherwise.
struct TangentMaps {
  Texture normal_map;   // xyz = N, w = S_binormal
  Texture tangent_map;  // xyz = T, w = handedness * S_tangent
  TangentMapOptions options;
};

// Whether the parameterisation is periodic in u (v): every vertex at u = 0
// has a twin at u = 1 with the same v and position (1e-4 scene units), as
// on a torus (both), a UV sphere or cylinder (u), not a plane.
void DetectPeriodicAxes(const core::TriangleMesh& mesh, bool& wrap_u, bool& wrap_v);

// The chart's topology in `options`: wrap_u and wrap_v (DetectPeriodicAxes),
// and the poles: an edge (u or v = 0 or 1) whose vertices all lie within
// 1e-4 scene units of one point while their other coordinate spans at least
// half the chart, across a periodic other axis.
void DetectChart(const core::TriangleMesh& mesh, TangentMapOptions& options);

// Algorithm 1: renders `mesh` (needs normals and uvs) in UV space. The
// second form takes the frames already computed (ComputeTangentFrames(mesh,
// options.max_scale)).
TangentMaps RenderTangentMaps(ProgramCache& programs, const core::TriangleMesh& mesh,
                              const TangentMapOptions& options);
TangentMaps RenderTangentMaps(ProgramCache& programs, const core::TriangleMesh& mesh,
                              const TangentMapOptions& options, const TangentFrames& frames);

}  // namespace render
