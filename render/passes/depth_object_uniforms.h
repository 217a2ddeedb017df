// The depth-object programs' uniforms (shaders/passes/depth_object*.glsl),
// looked up once per linked program (render/gl/uniform.h). One struct for the
// slice, fast-slice, ray and resolve programs: they share depth_object_core.glsl,
// and each lacks the others' own uniforms, which stay inactive handles.
// Set by ibr/depth_object*.cc and render/passes/depth_object_gpu.cc.
#pragma once

#include <glm/glm.hpp>

#include "render/gl/uniform.h"

namespace render {

struct DepthObjectUniforms {
  explicit DepthObjectUniforms(const Program& p)
      : depth_maps(p, "u_depth_maps"),
        color_maps(p, "u_color_maps"),
        map_count(p, "u_map_count"),
        active_count(p, "u_active_count"),
        view_ray(p, "u_view_ray"),
        view_height(p, "u_view_height"),
        inv255(p, "u_inv255"),
        required(p, "u_required"),
        subtexel_edge(p, "u_subtexel_edge"),
        world_from_box(p, "u_world_from_box"),
        cam_from_world(p, "u_cam_from_world"),
        clip_from_cam(p, "u_clip_from_cam"),
        slice_plane(p, "u_slice_plane"),
        clear_pass(p, "u_clear_pass"),
        box_from_cam(p, "u_box_from_cam"),
        ray_step(p, "u_ray_step"),
        skip_grid(p, "u_skip_grid"),
        skip_resolution(p, "u_skip_resolution"),
        accum_color(p, "u_accum_color"),
        accum_depth(p, "u_accum_depth"),
        visibility_tolerance(p, "u_visibility_tolerance"),
        refine(p, "u_refine"),
        plane0(p, "u_plane0"),
        plane_step(p, "u_plane_step") {}
  // depth_object_core.glsl (every program)
  Uniform<int> depth_maps;  // texture unit
  Uniform<int> color_maps;  // texture unit
  Uniform<int> map_count;
  Uniform<int> active_count;
  Uniform<glm::vec4> view_ray;
  Uniform<float> view_height;
  Uniform<float> inv255;
  Uniform<int> required;
  Uniform<float> subtexel_edge;
  // The slicing core (slice programs); u_clip_from_cam also FRAME_OUTPUT's resolve
  Uniform<glm::mat4> world_from_box;
  Uniform<glm::mat4> cam_from_world;
  Uniform<glm::mat4> clip_from_cam;
  // depth_object.frag.glsl (the paper's slice passes)
  Uniform<glm::vec4> slice_plane;
  Uniform<int> clear_pass;
  // depth_object_ray.frag.glsl
  Uniform<glm::mat4> box_from_cam;
  Uniform<float> ray_step;
  Uniform<int> skip_grid;  // texture unit
  Uniform<int> skip_resolution;
  // depth_object_resolve.frag.glsl
  Uniform<int> accum_color;  // texture unit
  Uniform<int> accum_depth;  // texture unit
  Uniform<float> visibility_tolerance;
  Uniform<int> refine;
  Uniform<glm::vec4> plane0;
  Uniform<float> plane_step;
};

}  // namespace render
