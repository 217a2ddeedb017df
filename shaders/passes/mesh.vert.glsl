#version 450 core
// Mesh rasterisation (render/passes/mesh_pass.h). Camera convention: x right, y down,
// z forward; v_cam_z is the depth we write out (camera z, scene units).
#include "common/mesh_attributes.glsl"

uniform mat4 u_world_from_object;
uniform mat4 u_cam_from_world;
uniform mat4 u_clip_from_cam;

out vec3 v_normal_world;
out vec3 v_p_in_cam;
out vec2 v_uv;

void main() {
  vec4 p_in_world = u_world_from_object * vec4(a_position, 1.0);
  vec4 p_in_cam = u_cam_from_world * p_in_world;
  v_p_in_cam = p_in_cam.xyz;
  // Normals: inverse-transpose of the object-to-world linear part.
  v_normal_world = transpose(inverse(mat3(u_world_from_object))) * a_normal;
  v_uv = a_uv;
  gl_Position = u_clip_from_cam * p_in_cam;
}
