// The slicing core, GPU side (Kautz-Seidel 2001, sec. 3). Included by every
// slicing pass; never copied. Slice vertices arrive in box coordinates
// (render/cores/slice_buffer.h), which are also the 3D texture coordinates of the
// sliced volume; for a displacement volume box z is the height, so the ramp
// value h_alpha of a fragment is its interpolated box z (sec. 3.2).

uniform mat4 u_world_from_box;
uniform mat4 u_cam_from_world;
uniform mat4 u_clip_from_cam;

// Places a slice vertex; returns clip position, writes the camera-space point.
vec4 SliceVertex(vec3 p_in_box, out vec3 p_in_cam) {
  vec4 p_in_world = u_world_from_box * vec4(p_in_box, 1.0);
  p_in_cam = (u_cam_from_world * p_in_world).xyz;
  return u_clip_from_cam * vec4(p_in_cam, 1.0);
}

// Places a slice vertex whose world position the pass computed itself: the
// slices of a volume whose box-to-world map is not affine (a mesh face's
// displacement volume extruded along interpolated normals, sec. 3).
vec4 SliceVertexWorld(vec3 p_in_world, out vec3 p_in_cam) {
  p_in_cam = (u_cam_from_world * vec4(p_in_world, 1.0)).xyz;
  return u_clip_from_cam * vec4(p_in_cam, 1.0);
}

// The paper's alpha test after ramp subtraction, used for ALL slicing
// directions: keep iff displacement - h_alpha > 0 (strict, so a height of 0
// is never drawn and masks the surface out; end of sec. 3.2).
// h_alpha is clamped at 0: interpolation can push a ramp value on the box's
// base a few ulps below 0, which would otherwise draw a height of 0.
bool SliceAlphaTest(float displacement, float h_alpha) {
  return displacement - max(h_alpha, 0.0) > 0.0;
}

// Full-size screen slices reach outside the box: there the paper's texture
// border has alpha 0, i.e. nothing is drawn.
bool InsideUnitBox(vec3 p_in_box) {
  return all(greaterThanEqual(p_in_box, vec3(0.0))) && all(lessThanEqual(p_in_box, vec3(1.0)));
}
