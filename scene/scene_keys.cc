#include "scene/scene_keys.h"

#include <fmt/format.h>

namespace scene {
namespace {

// Structural keys (parsed by the scene reader itself).
KeySpec Structural(std::string_view key, std::string_view type, std::string_view default_value,
                   std::string_view help) {
  return {key, type, default_value, help, /*effect=*/false};
}

std::vector<KeySpec> DepthObjectKeys() {
  return {
      Structural("images", "object", "(required)",
                 "where the maps come from: {\"dataset\": DIR} or {\"capture\": {\"shape\" | "
                 "\"mesh\" | \"shared_mesh\", \"rig\": \"cube\" | \"ring:N\" | \"sphere:N\", "
                 "\"size\": px}}"),
      {"slicing", "string", "orthogonal",
       "orthogonal | screen | ray: slices along the main axis, slices parallel to the screen, or "
       "one ray per pixel on the ray core"},
      {"slices", "integer or \"auto\"", "auto",
       "slices (slice paths) or ray steps (ray path); auto picks enough for one slice per map "
       "texel"},
      {"slice_path", "string", "exact",
       "exact | fast: the stencil path of Kautz-Seidel sec. 4, or "
       "one pass per slice with a combined test"},
      {"texturing", "string", "vdt",
       "vdt | visibility | none | vdt-paper: view-dependent texturing and its variants"},
      {"robust", "integer", "0", "k: a pixel stays inside when at most k maps reject it"},
      {"outside", "string", "pass",
       "pass | fail: what a map says about points outside its view frustum"},
      {"invalid_depth", "string", "empty",
       "empty | no-constraint: what a map texel without depth says"},
      {"refine_steps", "integer", "6",
       "bisection steps refining a ray hit (0..64, the ray core's range)"},
      {"max_maps", "integer", "0", "the nearest N maps per frame (0 = all)"},
      {"depth_lookup", "string", "subtexel on the ray path, else nearest",
       "subtexel | nearest: depth between map texels, or the nearest texel"},
  };
}

// Composite maps (Correa 2006 Fig. 5, eq. 9-10), the same on volumes and
// deform objects.
constexpr KeySpec kDeformationsKey = {
    "deformations", "list", "none (the keys above)",
    "instead of deformation/amount/width: [{\"name\": N, \"amount\": A, \"width\": W, "
    "\"placement\": \"tx,ty,tz[,rx,ry,rz[,scale]]\"}, ...], each placed in the object's "
    "deformation box (box units, degrees, about its centre)"};

}  // namespace

const std::vector<KeySpec>& CommonObjectKeys() {
  static const std::vector<KeySpec> keys = {
      Structural("type", "string", "(required)", "the object kind (the sections below)"),
      Structural("name", "string", "object_N", "shown in the viewer and in messages"),
      Structural("enabled", "bool", "true",
                 "false: named but not drawn; its passes, programs and textures are not built"),
      Structural("transform", "object", "identity",
                 "world_from_object: {\"translate\": [x, y, z], \"rotate_deg\": [x, y, z] (about "
                 "x, then y, then z), \"scale\": s or [sx, sy, sz]} or {\"matrix\": 3 rows of 4}"),
  };
  return keys;
}

const std::vector<ObjectKindSpec>& ObjectKinds() {
  static const std::vector<ObjectKindSpec> kinds = {
      {"depth-object", ObjectType::kDepthObject,
       "the intersection of many depth maps (Kautz-Seidel 2001, sec. 4)", DepthObjectKeys()},
      {"visual-hull", ObjectType::kVisualHull,
       "the intersection of the masks' cones (Kautz-Seidel 2001, sec. 5)", DepthObjectKeys()},
      {"displaced-mesh",
       ObjectType::kDisplacedMesh,
       "a height map displacing a mesh's surface (Kautz-Seidel 2001, sec. 3; Chen-Chang NCS)",
       {
           Structural("mesh", "object", "(required)",
                      "{\"shape\": \"torus\" | \"plane\" | \"sphere\"} or {\"file\": OBJ/PLY with "
                      "texture coordinates}"),
           Structural(
               "height", "object", "(required)",
               "{\"file\": 8/16-bit PNG or EXR in [0, 1]} or {\"generator\": bumps | noise | "
               "bricks | steps | spikes | constant, \"texels\": 256}"),
           Structural("texture", "string", "none", "a colour image on the mesh's UVs"),
           {"method", "string", "slices-orthogonal",
            "slices-surface | slices-orthogonal | slices-screen | ncs | relief | pom | crm | "
            "tessellated"},
           {"max_displacement", "number", "0.15", "height 1 in the mesh's units, in (0, 10]"},
           {"tiling", "number", "1", "height-map repeats across UV [0, 1], in (0, 1024]"},
           {"slices", "integer", "64", "slicing methods: slices per face volume (1..4096)"},
           {"steps", "integer", "32", "ray methods: linear-search steps (1..4096)"},
       }},
      {"mesh",
       ObjectType::kMesh,
       "a plain rasterised mesh",
       {
           Structural("mesh", "object", "(required)", "{\"shape\": NAME} or {\"file\": OBJ/PLY}"),
           Structural("texture", "string", "none", "a colour image on the mesh's UVs"),
       }},
      {"volume",
       ObjectType::kVolume,
       "direct volume rendering or an iso surface, displaced and cut (Correa, Silver, Chen 2006)",
       {
           Structural("volume", "string", "(one of volume, shared_volume)",
                      "a volume file (QVis .dat, NRRD .nrrd/.nhdr, NIfTI .nii/.nii.gz) or a "
                      "DICOM series folder, relative to the scene"),
           Structural("shared_volume", "string", "(one of volume, shared_volume)",
                      "a volume under the shared data folder"),
           Structural("transfer", "string or object",
                      "the preset named like the volume file, else a white ramp from the 50th "
                      "to the 99th percentile",
                      "a preset name (tooth, neghip, bucky, ramp, empty) or a transfer-function "
                      "JSON file (\"units\": \"data\" for points in the volume's units), or that "
                      "file's object inline (what the viewer saves for an edited one)"),
           {"deformation", "string", "none",
            "none, or a deformation of the deformations guide (twist | bend | pull | knife | "
            "peel | slices | seam | wave | clip | cutaway | wedge) or a comma list: one map each"},
           {"effect", "string", "none", "the same as deformation (its former name)"},
           {"amount", "number or list", "per deformation",
            "each deformation's amount (the deformations guide's table)"},
           {"width", "number or list", "per deformation",
            "each deformation's width (the deformations guide's table)"},
           {"placement", "string", "the volume's box",
            "tx,ty,tz[,rx,ry,rz[,scale]]: the deformations' box in the volume's box (box units, "
            "degrees, about its centre)"},
           kDeformationsKey,
           {"map_size", "integer", "64",
            "texels per axis of each deformation's displacement map (1..512)"},
           {"mode", "string", "dvr",
            "dvr, or iso:VALUE: the first surface at VALUE, in the data's units"},
           {"spacing", "number", "1", "sampling distance along a ray, in voxels"},
           {"displacement_bits", "integer", "16", "8 | 16 | 32: bits per displacement-map channel"},
           {"lighting", "string", "blended",
            "none | gradient | transformed | blended: normals at displaced samples (eq. 6-7)"},
           {"jacobian", "string", "precomputed",
            "precomputed | differences: how the map's Jacobian is found"},
       }},
      {"deform",
       ObjectType::kDeform,
       "a mesh deformed and cut by an inverse displacement (Correa, Silver, Chen 2007)",
       {
           Structural("mesh", "object", "(required)",
                      "{\"shape\": NAME} or {\"file\": F} or {\"shared_mesh\": REL}; closed, or "
                      "cap_holes"),
           {"deformation", "string", "twist",
            "twist | bend | pull | knife | peel | slices | seam | wave | clip | cutaway | wedge, "
            "or a comma list (summed)"},
           {"amount", "number or list", "per deformation",
            "strength of each deformation (comma list for several)"},
           {"width", "number or list", "per deformation",
            "width of each deformation, normalised units (comma list for several)"},
           {"cut", "string", "none", "none | hollow | solid | thick:T: how the cut alpha is drawn"},
           {"region", "string", "the mesh's bounds grown by 0.05",
            "x0,y0,z0,x1,y1,z1: the deformation box, normalised units (mesh centred, longest "
            "side 1)"},
           {"placement", "string", "0,0,0",
            "tx,ty,tz[,rx,ry,rz[,scale]]: moves the deformation in its box"},
           kDeformationsKey,
           {"step", "string", "fixed", "fixed | threshold:T | jacobian: the ray's step policy"},
           {"step_voxels", "number", "1", "ray step in distance-field voxels"},
           {"skip", "bool", "false",
            "skip empty space by the cut's distance (Correa 2007, sec. 6.2)"},
           {"skip_object", "bool", "true", "skip empty space by the object's distance field"},
           {"solid", "string", "csg", "csg | search: how a solid cut finds its surface"},
           {"resolution", "integer", "128", "distance-field voxels per axis (8..512)"},
           {"cap_holes", "bool", "false", "fill the boundary loops of an open mesh"},
           {"implicit", "string", "sdf", "sdf | depth-cube: the mesh's implicit (sec. 6.1)"},
           {"reach", "number", "the largest displacement",
            "how far the distance field reaches beyond the deformation box, normalised units "
            "(`ibr view --save-scene` writes the reach of the field it drew)"},
       }},
  };
  return kinds;
}

const ObjectKindSpec* FindObjectKind(std::string_view name) {
  for (const ObjectKindSpec& k : ObjectKinds()) {
    if (k.name == name) return &k;
  }
  return nullptr;
}

std::string ObjectKeysMarkdown() {
  auto table = [](const std::vector<KeySpec>& keys) {
    std::string md = "| key | type | default | meaning |\n|---|---|---|---|\n";
    for (const KeySpec& k : keys) {
      md += fmt::format("| `{}` | {} | {} | {} |\n", k.key, k.type, k.default_value, k.help);
    }
    return md;
  };
  std::string md = "#### Every object\n\n" + table(CommonObjectKeys());
  for (const ObjectKindSpec& kind : ObjectKinds()) {
    md += fmt::format("\n#### `\"type\": \"{}\"`: {}\n\n", kind.name, kind.source);
    md += table(kind.keys);
  }
  return md;
}

}  // namespace scene
