#include "ibr/deform_object.h"

#include <fmt/format.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <future>
#include <glm/gtc/matrix_transform.hpp>
#include <sstream>

#include "core/check.h"
#include "core/error.h"
#include "ibr/scene_renderer.h"
#include "render/cores/ray_core.h"

namespace ibr {
namespace {

// A number, or a string of comma-separated numbers; every one finite.
std::vector<double> Numbers(const scene::Settings& settings, const std::string& key) {
  const scene::Setting* s = settings.Find(key);
  if (s == nullptr) return {};
  if (s->value.is_number()) {
    const double v = s->value.get<double>();
    if (!std::isfinite(v)) settings.Fail(key, fmt::format("{} is not finite", s->value.dump()));
    return {v};
  }
  if (!s->value.is_string()) {
    settings.Fail(
        key, fmt::format("expected a number or a comma list of numbers, got {}", s->value.dump()));
  }
  const std::string text = s->value.get<std::string>();
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    double v = 0;
    try {
      size_t used = 0;
      v = std::stod(item, &used);
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      settings.Fail(key, fmt::format("'{}': '{}' is not a number", text, item));
    }
    if (!std::isfinite(v)) settings.Fail(key, fmt::format("'{}': '{}' is not finite", text, item));
    values.push_back(v);
  }
  if (values.empty()) settings.Fail(key, "no numbers given");
  return values;
}

// The text after "prefix:" as one finite number.
double Suffix(const scene::Settings& settings, const std::string& key, const std::string& text,
              size_t at) {
  scene::Settings one;
  one.Set(key, text.substr(at), settings.Find(key)->where);
  const std::vector<double> v = Numbers(one, key);
  if (v.size() != 1) settings.Fail(key, fmt::format("'{}': expected one number", text));
  return v[0];
}

bool Bool(const scene::Settings& settings, const std::string& key, bool fallback) {
  const scene::Setting* s = settings.Find(key);
  if (s == nullptr) return fallback;
  if (!s->value.is_boolean())
    settings.Fail(key, fmt::format("expected true or false, got {}", s->value.dump()));
  return s->value.get<bool>();
}

}  // namespace

void SetDeformationDefaults(core::Deformation& d) {
  const core::DeformationInfo& info = core::DeformationInfoOf(d.kind);
  d.amount = info.amount;
  d.width = info.width;
}

glm::dmat4 BoxPlacement(const std::vector<double>& p, const std::string& where) {
  if (p.size() != 3 && p.size() != 6 && p.size() != 7)
    core::ThrowInputError(where, "placement needs tx,ty,tz[,rx,ry,rz[,scale]], got {} numbers",
                          p.size());
  for (double v : p) {
    if (!std::isfinite(v)) core::ThrowInputError(where, "placement value {} is not finite", v);
  }
  const glm::dvec3 rotation = p.size() >= 6 ? glm::dvec3(p[3], p[4], p[5]) : glm::dvec3(0.0);
  const double scale = p.size() == 7 ? p[6] : 1.0;
  if (!(scale > 0)) core::ThrowInputError(where, "placement scale {} must be > 0", scale);
  return core::Placement::FromRegion(core::Box3d{glm::dvec3(0.0), glm::dvec3(1.0)}, rotation, scale,
                                     {p[0], p[1], p[2]})
      .object_from_box;
}

namespace {

// One entry of a "deformations" list.
core::Deformation DeformationFromJson(const nlohmann::json& j, const std::string& where) {
  if (!j.is_object() || !j.contains("name") || !j["name"].is_string()) {
    core::ThrowInputError(where,
                          "expected {{\"name\": NAME, \"amount\": A, \"width\": W, "
                          "\"placement\": P}}, got {}",
                          j.dump());
  }
  core::Deformation d;
  try {
    d.kind = core::DeformationKindFromName(j["name"].get<std::string>());
  } catch (const core::InputError& e) {
    throw core::InputError(fmt::format("{}/name: {}", where, e.what()));
  }
  SetDeformationDefaults(d);
  for (const auto& [key, value] : j.items()) {
    if (key == "name") continue;
    if (key == "amount" || key == "width") {
      if (!value.is_number() || !std::isfinite(value.get<double>()))
        core::ThrowInputError(where + "/" + key, "expected a finite number, got {}", value.dump());
      (key == "amount" ? d.amount : d.width) = value.get<double>();
    } else if (key == "placement") {
      std::vector<double> numbers;
      if (value.is_array()) {
        for (const nlohmann::json& v : value) {
          if (!v.is_number())
            core::ThrowInputError(where + "/placement", "{} is not a number", v.dump());
          numbers.push_back(v.get<double>());
        }
      } else {
        scene::Settings one;
        one.Set("placement", value, where + "/placement");
        numbers = Numbers(one, "placement");
      }
      d.parent_from_box = BoxPlacement(numbers, where + "/placement");
    } else {
      core::ThrowInputError(where + "/" + key, "unknown key (name, amount, width, placement)");
    }
  }
  try {
    d.Check();
  } catch (const core::InputError& e) {
    throw core::InputError(fmt::format("{}: {}", where, e.what()));
  }
  return d;
}

}  // namespace

std::vector<core::Deformation> DeformationsFrom(const scene::Settings& settings,
                                                const std::string& fallback, bool placement_key) {
  std::vector<core::Deformation> out;
  if (const scene::Setting* list = settings.Find("deformations")) {
    for (const char* key : {"deformation", "effect", "amount", "width", "placement"}) {
      if (settings.Has(key) && (placement_key || std::string(key) != "placement"))
        settings.Fail(key, "give either deformations or " + std::string(key));
    }
    if (!list->value.is_array() || list->value.empty())
      settings.Fail("deformations", "expected a non-empty list of deformations");
    for (size_t i = 0; i < list->value.size(); ++i)
      out.push_back(DeformationFromJson(list->value[i], fmt::format("{}/{}", list->where, i)));
    return out;
  }
  const std::string key =
      settings.Has("deformation") || !settings.Has("effect") ? "deformation" : "effect";
  std::vector<std::string> kinds;
  {
    std::stringstream in(settings.GetString(key, fallback));
    std::string item;
    while (std::getline(in, item, ',')) kinds.push_back(item);
    if (kinds.empty()) settings.Fail(key, "no deformation given");
  }
  const std::vector<double> amounts = Numbers(settings, "amount");
  const std::vector<double> widths = Numbers(settings, "width");
  glm::dmat4 placement(1.0);
  if (placement_key && settings.Has("placement")) {
    try {
      placement = BoxPlacement(Numbers(settings, "placement"), "placement");
    } catch (const core::InputError& e) {
      settings.Fail("placement", e.what());
    }
  }
  if (kinds.size() == 1 && kinds[0] == "none") {
    for (const char* k : {"amount", "width", "placement"}) {
      if (std::string(k) == "placement" && !placement_key) continue;
      if (settings.Has(k)) settings.Fail(k, "no deformation to apply it to");
    }
    return out;
  }
  for (const auto& [k, values] : {std::pair{"amount", &amounts}, std::pair{"width", &widths}}) {
    if (values->size() > kinds.size()) {
      settings.Fail(k,
                    fmt::format("{} values for {} deformation(s)", values->size(), kinds.size()));
    }
  }
  for (size_t i = 0; i < kinds.size(); ++i) {
    core::Deformation d;
    try {
      d.kind = core::DeformationKindFromName(kinds[i]);
    } catch (const core::InputError& e) {
      settings.Fail(key, e.what());
    }
    SetDeformationDefaults(d);
    if (i < amounts.size()) d.amount = amounts[i];
    if (i < widths.size()) d.width = widths[i];
    d.parent_from_box = placement;
    try {
      d.Check();
    } catch (const core::InputError& e) {
      settings.Fail(i < amounts.size() ? "amount" : i < widths.size() ? "width" : key, e.what());
    }
    out.push_back(d);
  }
  return out;
}

DeformObjectOptions DeformObjectOptionsFrom(const scene::Settings& settings) {
  DeformObjectOptions o;
  o.deformation.terms = DeformationsFrom(settings, "twist");
  if (o.deformation.terms.empty()) settings.Fail("deformation", "no deformation given");
  // The cut. A cut-away is nothing but its cut alpha: without a cut mode it
  // would leave the mesh as it is, so its default is the solid cut (eq. 6).
  const bool cut_away = std::any_of(o.deformation.terms.begin(), o.deformation.terms.end(),
                                    [](const core::Deformation& d) { return d.IsCutAway(); });
  std::string cut = settings.GetString("cut", cut_away ? "solid" : "none");
  if (cut.rfind("thick:", 0) == 0) {
    o.pass.thickness = static_cast<float>(Suffix(settings, "cut", cut, 6));
    if (!(o.pass.thickness > 0)) settings.Fail("cut", fmt::format("'{}': T must be > 0", cut));
    cut = "thick";
  }
  try {
    o.pass.cut = core::CutModeFromName(cut);
  } catch (const core::InputError& e) {
    settings.Fail("cut", e.what());
  }
  // The deformation box and its placement.
  if (settings.Has("region")) {
    const std::vector<double> r = Numbers(settings, "region");
    if (r.size() != 6) settings.Fail("region", "needs x0,y0,z0,x1,y1,z1");
    o.region = core::Box3d{{r[0], r[1], r[2]}, {r[3], r[4], r[5]}};
    for (int a = 0; a < 3; ++a) {
      if (!(o.region->hi[a] > o.region->lo[a]))
        settings.Fail("region", "needs x0 < x1, y0 < y1, z0 < z1");
    }
  }
  if (settings.Has("placement")) {
    const std::vector<double> p = Numbers(settings, "placement");
    if (p.size() != 3 && p.size() != 6 && p.size() != 7)
      settings.Fail("placement", "needs tx,ty,tz[,rx,ry,rz[,scale]]");
    o.translation = {p[0], p[1], p[2]};
    if (p.size() >= 6) o.rotation_deg = {p[3], p[4], p[5]};
    if (p.size() == 7) o.scale = p[6];
    if (!(o.scale > 0)) settings.Fail("placement", fmt::format("scale {} must be > 0", o.scale));
  }
  // The ray's steps.
  std::string step = settings.GetString("step", "fixed");
  if (step.rfind("threshold:", 0) == 0) {
    o.pass.threshold = static_cast<float>(Suffix(settings, "step", step, 10));
    step = "threshold";
  }
  try {
    o.pass.step_policy = render::RayStepPolicyFromName(step);
  } catch (const core::InputError& e) {
    settings.Fail("step", e.what());
  }
  o.pass.step_voxels = static_cast<float>(settings.GetDouble("step_voxels", o.pass.step_voxels));
  o.pass.skip_empty = Bool(settings, "skip", false);
  o.pass.skip_object = Bool(settings, "skip_object", true);
  const std::string solid = settings.GetString("solid", "csg");
  if (solid != "csg" && solid != "search")
    settings.Fail("solid", fmt::format("'{}' is not csg or search", solid));
  o.pass.solid_search = solid == "search";
  try {
    o.pass.Check();
  } catch (const core::InputError& e) {
    for (const char* key : {"step_voxels", "step", "cut"}) {
      if (settings.Has(key)) settings.Fail(key, e.what());
    }
    throw;
  }
  try {
    o.pass.implicit = render::DeformImplicitFromName(settings.GetString("implicit", "sdf"));
  } catch (const core::InputError& e) {
    settings.Fail("implicit", e.what());
  }
  o.sdf_resolution = settings.GetInt("resolution", o.sdf_resolution);
  if (o.sdf_resolution < 8 || o.sdf_resolution > 512)
    settings.Fail("resolution", fmt::format("{} outside 8..512", o.sdf_resolution));
  o.cap_holes = Bool(settings, "cap_holes", false);
  if (settings.Has("reach")) {
    o.sdf_reach = settings.GetDouble("reach", 0.0);
    if (!(*o.sdf_reach >= 0)) settings.Fail("reach", fmt::format("{} must be >= 0", *o.sdf_reach));
  }
  return o;
}

void NormaliseMesh(core::TriangleMesh& mesh, const std::string& where) {
  glm::vec3 lo, hi;
  mesh.Bounds(lo, hi);
  const float longest = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  if (!(longest > 0)) core::ThrowInputError(where, "the mesh has no extent");
  const glm::vec3 centre = 0.5f * (lo + hi);
  for (glm::vec3& p : mesh.positions) p = (p - centre) / longest;
}

core::Box3d DeformedBounds(const core::Box3d& mesh, const core::Box3d& box, double displacement) {
  return {glm::min(mesh.lo, box.lo) - displacement, glm::max(mesh.hi, box.hi) + displacement};
}

core::Placement DeformPlacement(const DeformObjectOptions& options,
                                const core::Box3d& mesh_bounds) {
  core::Box3d region = options.region ? *options.region : mesh_bounds.Grown(0.05);
  if (!options.region) {
    // Slices spread the slabs towards +x by period / (period - gap): the
    // default region leaves that room, so the last slab stays in the box.
    double spread = 1.0;
    for (const core::Deformation& d : options.deformation.terms) {
      if (d.kind == core::DeformationKind::kSlices && !d.Placed())
        spread = std::max(spread, d.width / (d.width - d.amount));
    }
    region.hi.x = region.lo.x + spread * (region.hi.x - region.lo.x);
  }
  return core::Placement::FromRegion(region, options.rotation_deg, options.scale,
                                     options.translation);
}

render::DepthCube MakeDepthCube(render::ProgramCache& programs, const core::TriangleMesh& mesh,
                                int size) {
  const MapSet maps =
      CaptureMaps(programs, capture::SceneMesh{mesh, {}, "deform mesh"}, "cube", size);
  IBR_CHECK_EQ(maps.maps.size(), 6u);
  render::DepthCube cube;
  for (const ImageMap& m : maps.maps) {
    IBR_CHECK(m.camera.orthographic);
    // (u, v, z) = (sx x + cx, sy y + cy, z) of the map's camera point.
    glm::dmat4 pixel_from_cam(1.0);
    pixel_from_cam[0][0] = m.camera.fx;
    pixel_from_cam[1][1] = m.camera.fy;
    pixel_from_cam[3] = glm::dvec4(m.camera.cx, m.camera.cy, 0.0, 1.0);
    cube.faces.push_back({m.depth, pixel_from_cam * m.cam_from_world});
  }
  // The rig's scale is size / (cube width): a texel is 1 / scale, the cube
  // (the far face, depth 0 on the near one) size / scale.
  cube.texel = 1.0 / maps.maps[0].camera.fx;
  cube.far = size * cube.texel;
  cube.Check("MakeDepthCube");
  return cube;
}

int64_t DeformObjectData::ImplicitBytes() const {
  return depth_cube.faces.empty() ? static_cast<int64_t>(sdf.values.size() * sizeof(float))
                                  : depth_cube.Bytes();
}

void DeformObjectOptions::Check() const {
  deformation.Check();
  pass.Check();
  if (!(scale > 0) || !std::isfinite(scale))
    core::ThrowInputError("DeformObjectOptions", "placement scale {} must be finite and > 0",
                          scale);
  if (sdf_resolution < 8 || sdf_resolution > 512)
    core::ThrowInputError("DeformObjectOptions", "resolution {} outside 8..512", sdf_resolution);
  if (deformation_resolution < 2 || deformation_resolution > 256) {
    core::ThrowInputError("DeformObjectOptions", "deformation resolution {} outside 2..256",
                          deformation_resolution);
  }
  if (sdf_reach && (!std::isfinite(*sdf_reach) || *sdf_reach < 0))
    core::ThrowInputError("DeformObjectOptions", "reach {} must be finite and >= 0", *sdf_reach);
}

namespace {

core::Box3d NormMeshBounds(const core::TriangleMesh& mesh) {
  glm::vec3 lo, hi;
  mesh.Bounds(lo, hi);
  return {glm::dvec3(lo), glm::dvec3(hi)};
}

// The deformation's largest displacement, its texture and what the frame can
// hold (d.placement set; the normalised mesh's bounds given).
void SampleDeformObject(DeformObjectData& d, const DeformObjectOptions& options,
                        const core::Box3d& mesh_bounds) {
  d.max_displacement =
      core::MaxObjectDisplacement(options.deformation, d.placement, options.deformation_resolution);
  d.texture = core::SampleDeformation(options.deformation, options.deformation_resolution);
  d.norm_bounds = DeformedBounds(mesh_bounds, d.placement.ObjectBounds(), d.max_displacement);
}

// The implicit of the normalised mesh: the distance field over the
// deformation box grown by the reach, or the depth cube.
struct Implicit {
  core::DistanceField sdf;
  render::DepthCube depth_cube;
  std::optional<core::TriangleMesh> capped;  // CappedMesh
  core::Placement placement;                 // the box it was built over
  double reach = 0.0;
  double seconds = 0.0;
};
Implicit BuildImplicit(const core::TriangleMesh& mesh, const core::Placement& placement,
                       double max_displacement, const DeformObjectOptions& options,
                       const std::string& where, bool progress, render::ProgramCache* programs,
                       int threads = 0) {
  const bool cube = options.pass.implicit == render::DeformImplicit::kDepthCube;
  if (progress) {
    std::fprintf(stderr, "deform: %zu triangles, max displacement %.4f; building the %s\n",
                 mesh.triangle_count(), max_displacement, cube ? "depth cube" : "distance field");
  }
  const auto start = std::chrono::steady_clock::now();
  // The same closedness rule for both implicits (open meshes refused unless
  // capped); the depth cube renders the capped mesh if holes were filled
  // (else the maps would look into them).
  const core::MeshDistance distance(mesh, options.cap_holes, where);
  const core::Box3d box = placement.ObjectBounds();
  Implicit i;
  i.placement = placement;
  i.capped = CappedMesh(distance);
  if (cube) {
    IBR_CHECK(programs != nullptr);  // the depth cube renders its maps
    i.depth_cube = MakeDepthCube(*programs, i.capped ? *i.capped : mesh, options.sdf_resolution);
  } else {
    core::DistanceFieldOptions sdf_options;
    sdf_options.resolution = options.sdf_resolution;
    sdf_options.progress = progress;
    sdf_options.threads = threads;
    // Grown by the reach (samples land up to the largest displacement out)
    // and two voxels for the normals' central differences.
    const double voxel =
        std::max({box.size().x, box.size().y, box.size().z}) / (options.sdf_resolution - 1);
    i.reach = std::max(options.sdf_reach.value_or(0.0), max_displacement);
    i.sdf = core::BuildDistanceField(distance, box.Grown(i.reach + 2 * voxel), sdf_options);
  }
  i.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return i;
}

void SetImplicit(DeformObjectData& d, Implicit i) {
  d.sdf = std::move(i.sdf);
  d.depth_cube = std::move(i.depth_cube);
  d.capped = std::move(i.capped);
  d.field_placement = i.placement;
  d.sdf_reach = i.reach;
  d.sdf_seconds = i.seconds;
  ++d.implicit_builds;
}

}  // namespace

struct DeformFieldBuild::Worker {
  std::future<Implicit> result;
};

DeformFieldBuild::DeformFieldBuild(std::shared_ptr<const DeformObjectData> data,
                                   const DeformObjectOptions& options, std::string where,
                                   int threads, int nice)
    : worker_(std::make_unique<Worker>()),
      placement_(data->placement),
      resolution_(options.sdf_resolution),
      cap_holes_(options.cap_holes),
      reach_(std::max(options.sdf_reach.value_or(0.0), 1.5 * data->max_displacement)) {
  IBR_CHECK(options.pass.implicit == render::DeformImplicit::kSdf);
  DeformObjectOptions build = options;
  build.sdf_reach = reach_;
  worker_->result = std::async(
      std::launch::async, [data = std::move(data), build, where = std::move(where), threads, nice] {
        // Linux: a thread's own niceness (the calling thread's alone).
        if (nice != 0) setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), nice);
        return BuildImplicit(data->mesh, data->placement, data->max_displacement, build, where,
                             /*progress=*/false, /*programs=*/nullptr, threads);
      });
}

DeformFieldBuild::~DeformFieldBuild() {
  if (worker_->result.valid()) worker_->result.wait();
}

bool DeformFieldBuild::Ready() const {
  return worker_->result.valid() &&
         worker_->result.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
}

bool DeformFieldBuild::Used() const { return !worker_->result.valid(); }

bool DeformFieldBuild::Serves(const DeformObjectOptions& options, const core::Placement& placement,
                              double max_displacement) const {
  return worker_->result.valid() && options.pass.implicit == render::DeformImplicit::kSdf &&
         placement.object_from_box == placement_.object_from_box &&
         options.sdf_resolution == resolution_ && options.cap_holes == cap_holes_ &&
         reach_ >= max_displacement && reach_ >= options.sdf_reach.value_or(0.0);
}

std::optional<core::TriangleMesh> CappedMesh(const core::MeshDistance& distance) {
  if (distance.capped_holes() == 0) return std::nullopt;
  core::TriangleMesh closed = distance.closed_mesh();
  core::SetAreaWeightedNormals(closed);
  return closed;
}

DeformObjectData MakeDeformObject(core::TriangleMesh mesh, const DeformObjectOptions& options,
                                  const std::string& where, bool progress,
                                  render::ProgramCache* programs) {
  DeformObjectData d;
  // object (the mesh file's frame) = centre + longest * normalised.
  glm::vec3 lo, hi;
  mesh.Bounds(lo, hi);
  const glm::dvec3 centre = 0.5 * (glm::dvec3(lo) + glm::dvec3(hi));
  const double longest = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  NormaliseMesh(mesh, where);
  d.object_from_norm = glm::scale(glm::translate(glm::dmat4(1.0), centre), glm::dvec3(longest));
  d.mesh = std::move(mesh);
  d.placement = DeformPlacement(options, NormMeshBounds(d.mesh));
  SampleDeformObject(d, options, NormMeshBounds(d.mesh));
  SetImplicit(d, BuildImplicit(d.mesh, d.placement, d.max_displacement, options, where, progress,
                               programs));
  return d;
}

DeformObjectChange UpdateDeformObject(DeformObjectData& data,
                                      const DeformObjectOptions& old_options,
                                      DeformObjectOptions& options, const std::string& where,
                                      render::ProgramCache* programs, bool defer_reach,
                                      DeformFieldBuild* prebuilt) {
  try {
    options.Check();
  } catch (const core::InputError& e) {
    throw core::InputError(fmt::format("{}: {}", where, e.what()));
  }
  DeformObjectChange change;
  // The default region depends on the deformation (slices): compare boxes.
  const bool placement = DeformPlacement(old_options, NormMeshBounds(data.mesh)).object_from_box !=
                         DeformPlacement(options, NormMeshBounds(data.mesh)).object_from_box;
  change.deformation = placement || old_options.deformation != options.deformation ||
                       old_options.deformation_resolution != options.deformation_resolution;
  change.pass = old_options.pass != options.pass;
  const bool cube = options.pass.implicit == render::DeformImplicit::kDepthCube;
  change.implicit = (cube && placement) || old_options.pass.implicit != options.pass.implicit ||
                    old_options.sdf_resolution != options.sdf_resolution ||
                    old_options.cap_holes != options.cap_holes ||
                    (!cube && old_options.sdf_reach != options.sdf_reach);
  // Everything new is built aside first: on an error nothing changes.
  DeformObjectData next = {};
  next.placement = placement ? DeformPlacement(options, NormMeshBounds(data.mesh)) : data.placement;
  next.max_displacement = data.max_displacement;
  if (change.deformation) SampleDeformObject(next, options, NormMeshBounds(data.mesh));
  // A field built over another box (the field's extent follows the box).
  if (!cube && data.field_placement.object_from_box != next.placement.object_from_box) {
    if (defer_reach && !change.implicit) {
      change.implicit_deferred = true;
    } else {
      change.implicit = true;
    }
  }
  // A field that does not reach as far as the new deformation needs.
  if (!cube && data.sdf_reach < next.max_displacement) {
    if (defer_reach && !change.implicit) {
      change.implicit_deferred = true;
    } else {
      change.implicit = true;
    }
  }
  std::optional<double> reach = options.sdf_reach;
  if (!cube && !change.implicit) {
    reach = data.sdf_reach;  // the field kept: the options make the same data
  } else if (!cube) {
    reach = std::max(reach.value_or(0.0), 1.5 * next.max_displacement);
  }
  std::optional<Implicit> implicit;
  // A field built in the background that serves the update replaces the
  // rebuild (or the kept field); while deferring only when it is done.
  if (!cube && (change.implicit || change.implicit_deferred) && prebuilt != nullptr &&
      prebuilt->Serves(options, next.placement, next.max_displacement) &&
      (!defer_reach || prebuilt->Ready())) {
    implicit = prebuilt->worker_->result.get();
    change.implicit = true;
    change.implicit_deferred = false;
    reach = implicit->reach;
  } else if (change.implicit) {
    DeformObjectOptions build = options;
    build.sdf_reach = reach;
    implicit = BuildImplicit(data.mesh, next.placement, next.max_displacement, build, where,
                             /*progress=*/false, programs);
  }
  // Commit.
  options.sdf_reach = reach;
  if (change.deformation) {
    data.placement = next.placement;
    data.max_displacement = next.max_displacement;
    data.texture = std::move(next.texture);
    data.norm_bounds = next.norm_bounds;
  }
  if (implicit) SetImplicit(data, std::move(*implicit));
  return change;
}

}  // namespace ibr
