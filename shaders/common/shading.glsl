// The head light every opaque pass shades with (mesh, relief/NCS/POM, and
// the passes that follow them): a two-sided light at the camera, 0.25 ambient
// + 0.75 diffuse. `p_in_cam` is the shaded point in camera space; with
// ORTHOGRAPHIC the light comes along the camera's z axis.
vec3 HeadLight(vec3 albedo, vec3 n_cam, vec3 p_in_cam) {
#ifdef ORTHOGRAPHIC
  vec3 to_eye = vec3(0.0, 0.0, -1.0);
#else
  vec3 to_eye = normalize(-p_in_cam);
#endif
  return albedo * (0.25 + 0.75 * abs(dot(n_cam, to_eye)));
}
