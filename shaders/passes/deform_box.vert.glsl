#version 450 core
// Deform pass, stage 2 (render/passes/deform_pass.h): the deformation box's
// faces; the fragment shader casts the ray.
layout(location = 0) in vec3 a_position;  // box units, [0, 1]^3

uniform mat4 u_object_from_box;
uniform mat4 u_cam_from_world;
uniform mat4 u_clip_from_cam;

out vec3 v_p_world;

void main() {
  vec4 p_world = u_object_from_box * vec4(a_position, 1.0);
  v_p_world = p_world.xyz;
  gl_Position = u_clip_from_cam * (u_cam_from_world * p_world);
}
