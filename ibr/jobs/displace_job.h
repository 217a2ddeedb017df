// `ibr displace` and the donut of `ibr demo` as library calls: one
// displacement-mapped base mesh (torus, plane, sphere, or the user's mesh with
// a height map and texture) drawn by one method of the method table
// (ibr/displaced_mesh.h), timed, optionally against the `tessellated` ground
// truth, written as a PNG (colour) and an EXR beside it (camera z).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "core/displacement_error.h"
#include "core/timing.h"
#include "ibr/displaced_mesh.h"
#include "ibr/views.h"
#include "render/gl/frame_timer.h"
#include "render/gl/shader_program.h"
#include "render/passes/pass.h"

namespace ibr {

// One method drawn (timed when `timer` is given) as a one-object scene
// (ibr::SceneRenderer, the displaced-mesh kind), its frame read back.
struct DisplacedDraw {
  render::Frame frame;
  core::TimingStats timing;  // empty when untimed
  std::string detail;        // DisplacedMeshRenderer::Detail, plus early-terminated pixels
};
// `say` gets the tessellated truth's plan (its subdivisions within the memory
// budget) when the method is `tessellated`. Needs a current context.
DisplacedDraw DrawDisplaced(render::ProgramCache& programs, const DisplacedMeshData& data,
                            const DisplacedMeshOptions& options, const ViewCamera& view,
                            const std::optional<render::FrameTimerOptions>& timer,
                            const std::function<void(const std::string&)>& say = {});

// A method's frame against the tessellated truth's from the same camera
// (core::CompareToGroundTruth), depth in height texels of data.height at
// `tiling` (core::HeightTexelWorldSize).
core::DisplacementError DisplacedError(const render::Frame& method, const render::Frame& truth,
                                       const DisplacedMeshData& data, float tiling);

// Everything `ibr displace` takes (its flags, in the data's own units).
struct DisplaceJob {
  std::string method = "slices-orthogonal";  // DisplacementMethodNames()
  std::string base = "torus";                // torus | plane | sphere
  std::string height = "bumps";              // core::HeightPatternFromName
  std::filesystem::path mesh;                // the user's OBJ/PLY with uvs (instead of `base`)
  std::filesystem::path height_map;          // the user's 8/16-bit PNG or EXR height map
  std::filesystem::path texture;             // optional colour texture
  float max_displacement = 0.15f;            // scene units (the torus tube radius is 0.4)
  float tiling = 2.0f;                       // the height map's repeats across uv [0, 1]
  float texture_tiling = 1.0f;  // the colour texture's: 1 = where the mesh's uvs put it
  int texels = 256;             // generated height map size, 4..4096
  int slices = 64;              // per volume
  int size = 512;               // pixels, square
  double elevation = 35;        // degrees above the plane perpendicular to `up`
  double azimuth = -60;         // degrees around `up`
  double distance = 0;          // camera distance from the bounds' centre, scene units (0 = framed)
  double fov = 40;              // field of view, degrees
  std::string up = "z";
  std::string background;  // "R,G,B" (0-255): composite onto an opaque colour; empty: none
  int frames = 7;          // timed frames (median), 0..1000; 0 = draw once, untimed
  bool unlit = false;      // the colour texture's plain colour, not lit
  std::filesystem::path out = "displace.png";  // the colour PNG; camera z beside it (.depth.exr)
  bool compare = false;                        // also render `tessellated` and report the error

  // Everything that needs no file and no context (InputError naming the flag).
  void Check() const;
  DisplacedMeshOptions PassOptions() const;
  OrbitCamera Orbit() const;
};

// "R,G,B", each an integer 0..255 (InputError naming `where` otherwise).
std::array<uint8_t, 3> ParseBackgroundRgb(const std::string& text, std::string_view where);
// Straight alpha over an opaque colour: alpha 255 everywhere after.
void CompositeOver(core::Image8& color, const std::array<uint8_t, 3>& background);

// Checks, loads, draws (and compares), refuses an empty image (the camera
// misses the mesh), writes the PNG and the EXR; one line per result through
// `say` ("displace: ..."). Needs a current context.
void RunDisplaceJob(render::ProgramCache& programs, const DisplaceJob& job,
                    const std::function<void(const std::string&)>& say);

}  // namespace ibr
