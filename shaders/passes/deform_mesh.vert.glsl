#version 450 core
// Deform pass, stage 1 (render/passes/deform_pass.h): the undeformed mesh
// outside the deformation box. The box's complement is not convex, so it is
// drawn as six convex pieces (u_piece), each an intersection of half-spaces
// in box coordinates u = M^-1 p that gl_ClipDistance clips exactly:
//   0: u.x < 0   1: u.x > 1   2: u.x in [0,1], u.y < 0   3: ..., u.y > 1
//   4: u.x, u.y in [0,1], u.z < 0   5: ..., u.z > 1
// u_piece = -1: no clipping (triangles wholly outside one face plane, drawn
// once; the pass classifies them on the CPU).
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;

uniform mat4 u_cam_from_world;
uniform mat4 u_clip_from_cam;
uniform mat4 u_box_from_object;
uniform int u_piece;

out vec3 v_normal_world;
out vec3 v_p_in_cam;
out vec3 v_p_world;  // = object space (the pass draws in object space)
out float gl_ClipDistance[6];

void main() {
  vec3 u = (u_box_from_object * vec4(a_position, 1.0)).xyz;
  for (int i = 0; i < 6; ++i) gl_ClipDistance[i] = 1.0;
  if (u_piece >= 0) {
    int axis = u_piece / 2;
    bool above = (u_piece % 2) == 1;
    for (int a = 0; a < axis; ++a) {  // inside the slab on the earlier axes
      gl_ClipDistance[2 * a] = u[a];
      gl_ClipDistance[2 * a + 1] = 1.0 - u[a];
    }
    gl_ClipDistance[5] = above ? u[axis] - 1.0 : -u[axis];  // outside on this axis
  }
  vec4 p_in_cam = u_cam_from_world * vec4(a_position, 1.0);
  v_p_in_cam = p_in_cam.xyz;
  v_p_world = a_position;
  v_normal_world = a_normal;
  gl_Position = u_clip_from_cam * p_in_cam;
}
