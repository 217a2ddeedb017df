// The depth-object programs' uniforms (shaders/passes/depth_object*.glsl),
// looked up once per linked program (render/gl/uniform.h). One struct for the
// slice, fast-slice, ray and resolve programs: they share depth_object_core.glsl,
// and each lacks the others' own uniforms, which stay inactive handles.
// Internal to ibr/depth_object*.cc.
#pragma once

#include <glm/glm.hpp>

#include "render/gl/uniform.h"

namespace ibr {

struct DepthObjectUniforms {
  explicit DepthObjectUniforms(const render::Program& p)
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
  render::Uniform<int> depth_maps;  // texture unit
  render::Uniform<int> color_maps;  // texture unit
  render::Uniform<int> map_count;
  render::Uniform<int> active_count;
  render::Uniform<glm::vec4> view_ray;
  render::Uniform<float> view_height;
  render::Uniform<float> inv255;
  render::Uniform<int> required;
  render::Uniform<float> subtexel_edge;
  // The slicing core (slice programs); u_clip_from_cam also FRAME_OUTPUT's resolve
  render::Uniform<glm::mat4> world_from_box;
  render::Uniform<glm::mat4> cam_from_world;
  render::Uniform<glm::mat4> clip_from_cam;
  // depth_object.frag.glsl (the paper's slice passes)
  render::Uniform<glm::vec4> slice_plane;
  render::Uniform<int> clear_pass;
  // depth_object_ray.frag.glsl
  render::Uniform<glm::mat4> box_from_cam;
  render::Uniform<float> ray_step;
  render::Uniform<int> skip_grid;  // texture unit
  render::Uniform<int> skip_resolution;
  // depth_object_resolve.frag.glsl
  render::Uniform<int> accum_color;  // texture unit
  render::Uniform<int> accum_depth;  // texture unit
  render::Uniform<float> visibility_tolerance;
  render::Uniform<int> refine;
  render::Uniform<glm::vec4> plane0;
  render::Uniform<float> plane_step;
};

}  // namespace ibr
