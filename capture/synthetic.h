// Synthetic capture: render a mesh (a file through assimp, or an analytic
// shape) from a camera rig with the reference rasteriser (render/passes/mesh_pass.h)
// and write a dataset (colour, camera-z depth, mask, world normals). Uses GL:
// a context must be current. Deterministic: same inputs, same files.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "capture/camera.h"
#include "capture/dataset.h"
#include "core/image.h"
#include "core/mesh.h"
#include "render/gl/shader_program.h"

namespace capture {

// A mesh to capture, in world coordinates, with an optional RGBA8 texture
// (row 0 = top of the picture file).
struct SceneMesh {
  core::TriangleMesh mesh;
  core::Image8 texture;  // empty = untextured
  std::string source;    // file path or "shape:NAME", for messages and info
};

// What a load does with textures: kLoad finds the mesh's texture (below),
// kSkip loads geometry only (--truth-mesh, distance truths) and says nothing
// about textures.
enum class MeshTextures { kLoad, kSkip };

// Loads a mesh file: PLY through core/ply_io.h (faces and triangle strips,
// element counts checked), OBJ/OFF/STL/... through assimp (triangulated; for
// OBJ, OFF and STL the triangle count checked against what the file declares,
// capture/mesh_counts.h, a truncated file refused). Smooth normals are made
// where missing, v flipped to the image convention. Memory is checked against
// the budget (core/memory_budget.h) before the file is read.
// Textured when the mesh has UVs and a texture is found: `texture` if given
// (it must load; it overrides the materials'), else the first readable
// material texture (Windows paths such as ".\x.jpg" normalised, then its file
// name beside the mesh), else "<stem>_texture.png", "<stem>.png" or
// "<stem>.jpg" beside the mesh (Spot's layout). A material texture that is
// missing or unreadable is a warning naming the mesh and the paths tried,
// never an error: the geometry is right without it.
SceneMesh LoadSceneMesh(const std::filesystem::path& path,
                        const std::filesystem::path& texture = {},
                        MeshTextures textures = MeshTextures::kLoad);

// Analytic shapes: "sphere" (radius 1), "torus" (R 1, r 0.4, around z), "box"
// (half extents 1, 0.7, 0.5), "cup" (radius 1, height 1.2, wall 0.12, opens
// to +z), "mug" (the cup with a torus handle, R 0.35, r 0.08, in the
// xz-plane on +x), finely tessellated so facets sag < 1e-4 of their size.
SceneMesh MakeShapeScene(std::string_view name);
// The shapes above with an analytic distance (the mug has none).
std::vector<std::string> ShapeNames();

// A deterministic colour value-noise texture, RGBA8: five octaves of
// width/64 .. width/4 cells across, nearly equal weights, contrast stretched.
// Periodic in x. Feature-rich for SIFT: the "noise" backdrop uses it, and a
// SceneMesh with UVs can wear it (SfM tests).
core::Image8 NoiseTexture(int width, int height, uint32_t seed);

// "cube" (six orthographic faces of the bounding cube, Kautz-Seidel 2001
// sec. 4), "ring:N" (N perspective views on a circle around the up axis),
// "sphere:N" (N perspective views on a Fibonacci sphere).
struct RigSpec {
  enum class Kind { kCube, kRing, kSphere };
  Kind kind = Kind::kCube;
  int count = 6;
  // Throws core::InputError on anything else (N in 1..1000).
  static RigSpec Parse(std::string_view text);
  std::string ToString() const;
};

struct CaptureOptions {
  int size = 512;                  // pixels, square images; 16..8192
  std::string rig = "cube";        // RigSpec::Parse syntax
  double fov_deg = 40;             // perspective rigs: field of view, degrees (typical lens)
  double margin = 0.05;            // padding of the bounding cube / sphere, fraction of its size
  double ring_elevation_deg = 20;  // ring rigs: camera height above the equator, degrees
  glm::dvec3 up{0, 1, 0};          // world up for ring/sphere rigs (OBJ meshes are y-up)
  bool shade = true;               // Lambert head light (off: flat albedo)
  glm::vec4 base_color{0.8f, 0.8f, 0.8f, 1.0f};  // untextured meshes
  // Colour behind the object: "black", or "noise": a backdrop sphere around
  // the scene (centred on the bounds, poles along `up`, radius 2x the
  // farthest camera) with a deterministic multi-octave value-noise texture,
  // unshaded. World-fixed texture gives SIFT something to match when the
  // object alone has too few features (COLMAP SfM tests). Colour only: depth,
  // mask and normals still see the object alone.
  std::string background = "black";
  // A depth sensor's errors applied to every view (capture/sensor_model.h
  // spec, e.g. "sigma=0.3%,holes=0.02,edge=1"); empty = exact depth.
  std::string noise;
  void Check() const;
};

struct RigView {
  std::string name;
  Camera camera;
  Rigid3 cam_from_world;
  double near = 0, far = 0;  // clip range along camera z, scene units
};

// The rig's views around `bounds`, in a fixed order.
std::vector<RigView> MakeRig(const RigSpec& rig, const Bounds& bounds,
                             const CaptureOptions& options);

struct CapturedView {
  core::Image8 color;   // RGB
  core::ImageF depth;   // camera z, 0 = empty
  core::Image8 mask;    // 255 = object
  core::ImageF normal;  // world-frame unit normal facing the camera, 0 = empty
};

// Renders one view (GL context current).
CapturedView RenderView(render::ProgramCache& programs, const SceneMesh& scene, const RigView& view,
                        const CaptureOptions& options);

// The memory a capture holds at its peak (one view in flight: frame target,
// readback and the written images, plus the mesh and texture), in bytes.
uint64_t CaptureBytes(const SceneMesh& scene, const CaptureOptions& options);

// Renders every rig view and writes the dataset to `out` (staged: nothing is
// left on failure). `progress(i, n, name)` is called after each view. Checks
// CaptureBytes against the memory budget first; InputError when every view
// is empty (the mesh covers no pixel from any camera).
Dataset CaptureDataset(render::ProgramCache& programs, const SceneMesh& scene,
                       const CaptureOptions& options, const std::filesystem::path& out,
                       const std::function<void(int, int, const std::string&)>& progress = {});

}  // namespace capture
