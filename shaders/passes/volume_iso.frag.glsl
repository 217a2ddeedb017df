#version 450 core
// Volume pass, iso mode: the first hit of the displaced field at an iso value,
// marched by the shared ray core from the proxy box's back faces
// (render/passes/volume_pass.h).
#include "cores/slicing_core.glsl"
#include "passes/volume_core.glsl"

uniform float u_iso;  // normalised scalar

// Ray-core contract: > 0 empty, <= 0 solid. Cut space (mask < 0.5) is empty.
float RayField(vec3 p_in_box) {
  Displaced d = VolumeDisplace((u_tex_from_proxy * vec4(p_in_box, 1.0)).xyz);
  if (d.alpha < 0.5) return 1.0;
  return u_iso - VolumeSample(d.p).a;
}

#include "cores/ray_core.glsl"

in vec3 v_p_in_box;
in vec3 v_p_in_cam;

uniform bool u_orthographic;
uniform vec3 u_eye_in_box;       // perspective: the eye in proxy-box coordinates
uniform vec3 u_view_dir_in_box;  // orthographic: the view direction, one world unit long
uniform mat4 u_box_from_world_linear;  // world vector -> box vector (linear part)
uniform mat4 u_cam_from_box;
uniform float u_step_world;      // linear-search step, world units

layout(location = 0) out vec4 o_color;
layout(location = 1) out float o_camera_z;
layout(location = 2) out vec4 o_normal;  // world, unit
layout(r32ui) uniform coherent uimage2D u_outcome_flags;  // render::BindOutcomeImage

void main() {
  vec3 o = v_p_in_box;
  vec3 dir;
  if (u_orthographic) {
    dir = u_view_dir_in_box;
  } else {
    // One world unit along the viewing ray, in box coordinates.
    vec3 dir_world_unscaled = (inverse(u_box_from_world_linear) * vec4(o - u_eye_in_box, 0.0)).xyz;
    dir = (u_box_from_world_linear * vec4(normalize(dir_world_unscaled), 0.0)).xyz;
  }
  vec2 t = RayBoxInterval(o, dir, vec3(0.0), vec3(1.0));
  // Only the exit (back) face starts a ray: rasterised front faces discard.
  if (abs(t.y) > abs(t.x)) discard;
  float t_start = t.x;
  if (!u_orthographic) t_start = max(t_start, dot(u_eye_in_box - o, dir) / dot(dir, dir));
  if (!(t_start < 0.0)) discard;
  RayMarch r;
  r.origin = o + t_start * dir;
  r.dir = dir;
  r.t_max = -t_start;
  r.step = u_step_world;
  RayResult res = RayMarchRun(r);
  imageAtomicOr(u_outcome_flags, ivec2(gl_FragCoord.xy), 1u << res.outcome);
  if (res.outcome != RAY_OUTCOME_HIT) discard;
  vec4 p_cam = u_cam_from_box * vec4(res.p, 1.0);
  vec4 clip = u_clip_from_cam * p_cam;
  gl_FragDepth = 0.5 * (clip.z / clip.w) + 0.5;
  o_camera_z = p_cam.z;
  Displaced d = VolumeDisplace((u_tex_from_proxy * vec4(res.p, 1.0)).xyz);
  vec3 n = VolumeNormal(d, VolumeSample(d.p).xyz);
  o_normal = vec4(n, 0.0);
  o_color = vec4(VolumeShadeWithNormal(vec3(0.92, 0.88, 0.8), n), 1.0);
}
