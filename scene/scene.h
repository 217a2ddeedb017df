// Scene files (JSON, "version": 1): cameras, lights and a list of objects,
// each with a transform and the effect that draws it. CPU only: parse ->
// plain data; ibr/scene_renderer.h turns it into passes. The reader checks
// the schema (keys, types, object types, referenced files); the effects'
// option values are checked where they become options structs
// (ibr/scene_options.h), with the same error form:
//   "ReadScene: 'FILE' /objects/1/slices: what was wrong"
// naming the file and the JSON pointer (RFC 6901) of the offending value.
//
// Schema (every key optional unless marked *):
// {
//   "version": 1,                                          *
//   "description": "text",
//   "cameras": one of                                      *
//     {"orbit": {"count": 8, "size": 512, "elevation_deg": 20, "fov_deg": 40, "up": [0, 1, 0]}}
//         turntable around the bounds of all objects
//     {"dataset": "DIR", "size": 0}     a dataset's cameras (size: width in px, 0 = their own)
//     {"list": [{"name": "a"*, "width"*, "height"*, "fx"*, "fy"*, "cx"*, "cy"*,
//                "orthographic": false, "cam_from_world"*: [[r00, r01, r02, tx], [..], [..]]}]}
//   "lights": [{"type": "head"}]        the head light every pass shades with (the default)
//   "objects": [                                           *
//     {"type"*: "depth-object" | "visual-hull",            Kautz-Seidel 2001, sec. 4-5
//      "images"*: {"dataset": "DIR"} or {"capture": {"shape": S | "mesh": FILE | "shared_mesh":
//      REL,
//                                                    "rig": "cube", "size": 512}},
//      effect keys: slicing, slice_path, slices, texturing, robust, outside, invalid_depth,
//                   refine_steps, max_maps, depth_lookup},
//     {"type"*: "displaced-mesh",
//      "mesh"*: {"shape": "torus" | "plane" | "sphere"} or {"file": "OBJ/PLY with uvs"},
//      "height"*: {"file": "8/16-bit PNG or EXR"} or {"generator": "bumps", "texels": 256},
//      "texture": "colour image",
//      effect keys: method (slices-surface | slices-orthogonal | slices-screen | ncs | relief |
//                   pom | crm | tessellated), max_displacement, tiling, slices, steps},
//     {"type"*: "mesh", "mesh"*: as above, "texture": FILE}      a plain rasterised mesh
//     {"type"*: "volume",                                 Correa, Silver, Chen 2006
//      "volume"*: "QVis .dat or NRRD .nrrd/.nhdr" (or "shared_volume": REL, under the shared
//                 data folder),
//      "transfer": preset (tooth, neghip, bucky, ramp, empty), JSON file or that file's object
//                  inline (default: the preset named like the volume file, else ramp),
//      effect keys: effect (none | peel | slices | seam | pull | wave), map_size, mode (dvr |
//                   iso:VALUE), spacing (voxels), displacement_bits (8 | 16 | 32), lighting
//                   (none | gradient | transformed | blended), jacobian (precomputed |
//                   differences)}; the object frame is the volume's box scaled to its extent
//      and centred at the origin; DVR volumes are drawn after the opaque objects
//     {"type"*: "deform",                                 Correa, Silver, Chen 2007
//      "mesh"*: {"shape": S} or {"file": F} or {"shared_mesh": REL} (closed, or cap_holes),
//      effect keys (ibr/deform_object.h; as `ibr deform`'s flags): deformation (twist | bend |
//                   pull | knife | peel, or a comma list), amount, width (a number or a comma
//                   list), cut (none | hollow | solid | thick:T), region ("x0,y0,z0,x1,y1,z1"),
//                   placement ("tx,ty,tz[,rx,ry,rz[,scale]]"), step (fixed | threshold:T |
//                   jacobian), step_voxels, skip (bool), resolution, cap_holes (bool),
//                   implicit (sdf | depth-cube)};
//      the object frame is the mesh file's (the world of `ibr deform`); regions and widths
//      are in the normalised units (mesh centred, longest side 1)
//     common keys: "name" (default "object_N"), "enabled" (default true; false = named but
//       not drawn: its passes, programs and textures are not built), "transform":
//       {"translate": [x, y, z], "rotate_deg": [x, y, z] (about x, then y, then z),
//        "scale": s or [sx, sy, sz]} or {"matrix": [[4 numbers] x 3 rows]} (world_from_object)
//   ]
// }
// Relative file names are relative to the scene file's folder; "shared_mesh"
// and "shared_volume" are relative to the shared data folder (../shared/data or $IBR_SHARED_DATA).
#pragma once

#include <filesystem>
#include <glm/glm.hpp>
#include <iosfwd>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace scene {

constexpr int kSceneVersion = 1;

// An effect's option values as written (JSON scalars), each with where it came
// from ("ReadScene: 'FILE' /objects/0/slices", or "--slices" for a command
// line). The function that turns them into an options struct reads them
// through Get* and names `where` in its errors.
struct Setting {
  nlohmann::json value;
  std::string where;
};
class Settings {
 public:
  void Set(const std::string& key, nlohmann::json value, std::string where);
  bool Has(const std::string& key) const { return values_.count(key) > 0; }
  void Erase(const std::string& key) { values_.erase(key); }
  const Setting* Find(const std::string& key) const;
  // The value if present (InputError naming `where` on a wrong type), else `fallback`.
  std::string GetString(const std::string& key, const std::string& fallback) const;
  int GetInt(const std::string& key, int fallback) const;
  double GetDouble(const std::string& key, double fallback) const;
  // InputError "WHERE: what" for the key's value.
  [[noreturn]] void Fail(const std::string& key, const std::string& what) const;
  const std::map<std::string, Setting>& values() const { return values_; }

 private:
  std::map<std::string, Setting> values_;
};

// A mesh: an analytic shape by name, or a file.
struct MeshSource {
  std::string shape;           // "torus", "plane", "sphere", ... or empty
  std::filesystem::path file;  // OBJ/PLY, absolute (resolved), or empty
  std::string where;           // for errors when loading
};

struct HeightSource {
  std::filesystem::path file;  // 8/16-bit PNG or EXR, 1 channel used; or empty
  std::string generator;       // core::HeightPatternFromName name, or empty
  int texels = 256;            // generator resolution
  std::string where;
};

// Where a depth object's / visual hull's maps come from.
struct ImageSource {
  std::filesystem::path dataset;  // a dataset directory, or empty
  // ... or a synthetic capture of a mesh (capture::MakeRig)
  MeshSource capture_mesh;
  std::string capture_rig = "cube";
  int capture_size = 512;
};

enum class ObjectType { kDepthObject, kVisualHull, kDisplacedMesh, kMesh, kVolume, kDeform };
std::string ObjectTypeName(ObjectType type);

struct Object {
  std::string name;
  ObjectType type = ObjectType::kMesh;
  bool enabled = true;
  glm::dmat4 world_from_object{1.0};
  ImageSource images;             // depth object / visual hull
  MeshSource mesh;                // displaced mesh / mesh
  HeightSource height;            // displaced mesh
  std::filesystem::path texture;  // optional colour texture (displaced mesh / mesh)
  std::filesystem::path volume;   // volume: QVis .dat or NRRD file (resolved)
  Settings settings;              // the effect's options (see the schema)
  std::string where;              // "ReadScene: 'FILE' /objects/N"
};

struct ExplicitCamera {
  std::string name;
  int width = 0, height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;  // pixels (orthographic: pixels per scene unit)
  bool orthographic = false;
  glm::dmat4 cam_from_world{1.0};
};

struct Cameras {
  enum class Kind { kOrbit, kDataset, kList } kind = Kind::kOrbit;
  // kOrbit
  int orbit_count = 8, orbit_size = 512;
  double orbit_elevation_deg = 20, orbit_fov_deg = 40;
  glm::dvec3 orbit_up{0, 1, 0};
  // kDataset
  std::filesystem::path dataset;
  int dataset_size = 0;  // output width, 0 = the cameras' own
  // kList
  std::vector<ExplicitCamera> list;
};

struct Light {
  std::string type = "head";
};

struct Scene {
  std::string name;  // the file name (for messages)
  std::string description;
  Cameras cameras;
  std::vector<Light> lights;
  std::vector<Object> objects;
};

struct ReadOptions {
  std::filesystem::path base_dir;     // relative file names resolve against it
  std::filesystem::path shared_data;  // "shared_mesh" resolves against it
  bool check_files =
      true;  // referenced files must exist (off: embedded scenes listed without data)
};

// `name` names the source in errors (the file path). InputError on any
// schema violation, naming `name` and the JSON pointer.
Scene ReadScene(std::istream& in, const std::string& name, const ReadOptions& options);
// Opens the file; base_dir = its folder.
Scene ReadScene(const std::filesystem::path& path, const std::filesystem::path& shared_data);

}  // namespace scene
