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
      {"robust", "integer", "0", "k: a pixel stays inside when at most k maps reject it (>= 0)"},
      {"outside", "string", "pass",
       "pass | fail: what a map says about points outside its view frustum"},
      {"invalid_depth", "string", "empty",
       "empty | no-constraint: what a map texel without depth says"},
      {"refine_steps", "integer", "6", "bisection steps refining a ray hit (the ray core's range)",
       true, "", KeyRange{0, 64}},
      {"max_maps", "integer", "0", "the nearest N maps per frame (0 = all)", true, "",
       KeyRange{0, 4096}},
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
           {"max_displacement", "number", "0.15", "height 1 in the mesh's units", true, "",
            KeyRange{0, 10, /*lo_open=*/true}},
           {"tiling", "number", "1", "height-map repeats across UV [0, 1]", true, "",
            KeyRange{0, 1024, /*lo_open=*/true}},
           {"slices", "integer", "64", "slicing methods: slices per face volume", true, "",
            KeyRange{1, 4096}},
           {"steps", "integer", "32", "ray methods: linear-search steps", true, "",
            KeyRange{1, 4096}},
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
           {"deformation", "comma list", "none",
            "none, or a deformation of the deformations guide (twist | bend | pull | knife | "
            "peel | slices | seam | wave | clip | cutaway | wedge) or a comma list: one map each",
            true, "--deformation,--effect"},
           {"effect", "string", "none", "the same as deformation (its former name)"},
           {"amount", "number or list", "per deformation",
            "each deformation's amount (the deformations guide's table)", true, "--amount"},
           {"width", "number or list", "per deformation",
            "each deformation's width (the deformations guide's table)", true, "--width"},
           {"placement", "string", "the volume's box",
            "tx,ty,tz[,rx,ry,rz[,scale]]: the deformations' box in the volume's box (box units, "
            "degrees, about its centre)",
            true, "--placement"},
           kDeformationsKey,
           {"map_size", "integer", "64", "texels per axis of each deformation's displacement map",
            true, "--map-size", KeyRange{1, 512}},
           {"mode", "string", "dvr",
            "dvr, or iso:VALUE: the first surface at VALUE, in the data's units", true, "--mode"},
           {"spacing", "number", "1", "sampling distance along a ray, in voxels", true, "--spacing",
            KeyRange{0.05, 64}},
           {"displacement_bits", "integer", "16", "8 | 16 | 32: bits per displacement-map channel",
            true, "--displacement-bits"},
           {"lighting", "string", "blended",
            "none | gradient | transformed | blended: normals at displaced samples (eq. 6-7)", true,
            "--lighting"},
           {"jacobian", "string", "precomputed",
            "precomputed | differences: how the map's Jacobian is found", true, "--jacobian"},
       }},
      {"deform",
       ObjectType::kDeform,
       "a mesh deformed and cut by an inverse displacement (Correa, Silver, Chen 2007)",
       {
           Structural("mesh", "object", "(required)",
                      "{\"shape\": NAME} or {\"file\": F} or {\"shared_mesh\": REL}; closed, or "
                      "cap_holes"),
           {"deformation", "comma list", "twist",
            "twist | bend | pull | knife | peel | slices | seam | wave | clip | cutaway | wedge, "
            "or a comma list (summed)",
            true, "--deformation"},
           {"amount", "number or list", "per deformation",
            "strength of each deformation (comma list for several)", true, "--amount"},
           {"width", "number or list", "per deformation",
            "width of each deformation, normalised units (comma list for several)", true,
            "--width"},
           {"cut", "string", "none",
            "none | hollow | solid | thick:T: how the cut alpha is drawn (clip, cutaway, wedge: "
            "solid unless given)",
            true, "--cut"},
           {"region", "string", "the mesh's bounds grown by 0.05",
            "x0,y0,z0,x1,y1,z1: the deformation box, normalised units (mesh centred, longest "
            "side 1)",
            true, "--region"},
           {"placement", "string", "0,0,0",
            "tx,ty,tz[,rx,ry,rz[,scale]]: moves the deformation in its box", true, "--placement"},
           kDeformationsKey,
           {"step", "string", "fixed", "fixed | threshold:T | jacobian: the ray's step policy",
            true, "--step"},
           {"step_voxels", "number", "1", "ray step in distance-field voxels", true,
            "--step-voxels", KeyRange{0.01, 64}},
           {"skip", "bool", "false",
            "skip empty space by the cut's distance (Correa 2007, sec. 6.2)", true, "--skip"},
           {"skip_object", "bool", "true", "skip empty space by the object's distance field", true,
            "--skip-object"},
           {"solid", "string", "csg", "csg | search: how a solid cut finds its surface", true,
            "--solid"},
           {"resolution", "integer", "128", "distance-field voxels per axis", true, "--resolution",
            KeyRange{8, 512}},
           {"cap_holes", "bool", "false", "fill the boundary loops of an open mesh", true,
            "--cap-holes"},
           {"implicit", "string", "sdf", "sdf | depth-cube: the mesh's implicit (sec. 6.1)", true,
            "--implicit"},
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

std::string RangeText(const KeyRange& r) {
  return fmt::format("{}{}, {}{}", r.lo_open ? "(" : "[", r.lo, r.hi, r.hi_open ? ")" : "]");
}

std::string ObjectKeysMarkdown() {
  auto table = [](const std::vector<KeySpec>& keys) {
    std::string md =
        "| key | type | default | range | meaning | flag |\n|---|---|---|---|---|---|\n";
    for (const KeySpec& k : keys) {
      md += fmt::format("| `{}` | {} | {} | {} | {} | {} |\n", k.key, k.type, k.default_value,
                        k.range ? RangeText(*k.range) : std::string(), k.help,
                        k.flag.empty() ? std::string() : fmt::format("`{}`", k.flag));
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
