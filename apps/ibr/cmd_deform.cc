// `ibr deform MESH`: a mesh deformed and cut by the deform pass (Correa,
// Silver, Chen 2007); flags -> bench::DeformRunOptions -> bench::RunDeform.
#include <fmt/format.h>

#include <sstream>
#include <string>
#include <vector>

#include "apps/ibr/commands.h"
#include "bench/deform_bench.h"
#include "core/error.h"
#include "render/gl/context.h"
#include "render/passes/pass.h"

namespace apps {
namespace {

struct DeformFlags {
  std::string mesh;
  bool cap_holes = false;
  std::vector<std::string> deformations = {"twist"};
  std::vector<double> amounts, widths;
  std::string cut = "none";
  std::string region, placement;
  std::string step = "fixed";
  std::string implicit = "sdf";
  float step_voxels = 1.0f;
  bool skip = false;
  int resolution = 128;
  int size = 512;
  double azimuth = 30, elevation = 20;
  std::string cameras;
  std::string out;
};

std::vector<double> ParseNumbers(const std::string& text, const char* flag) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      size_t used = 0;
      values.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      core::ThrowInputError("ibr deform", "{} '{}': '{}' is not a number", flag, text, item);
    }
  }
  return values;
}

// Default amount and width per kind (normalised box units; radians).
void Defaults(core::Deformation& d) {
  switch (d.kind) {
    case core::DeformationKind::kTwist:
      d.amount = 2.0, d.width = 0.35;
      break;
    case core::DeformationKind::kBend:
      d.amount = 0.8, d.width = 0.0;
      break;
    case core::DeformationKind::kPull:
      d.amount = 0.5, d.width = 0.03;
      break;
    case core::DeformationKind::kKnife:
      d.amount = 0.15, d.width = 0.6;
      break;
    case core::DeformationKind::kPeel:
      d.amount = 2.4, d.width = 0.15;
      break;
  }
}

void RunDeformCommand(const DeformFlags& f) {
  bench::DeformRunOptions o;
  o.mesh = f.mesh;
  o.cap_holes = f.cap_holes;
  for (size_t i = 0; i < f.deformations.size(); ++i) {
    core::Deformation d;
    d.kind = core::DeformationKindFromName(f.deformations[i]);
    Defaults(d);
    if (i < f.amounts.size()) d.amount = f.amounts[i];
    if (i < f.widths.size()) d.width = f.widths[i];
    o.deformation.terms.push_back(d);
  }
  std::string cut = f.cut;
  if (cut.rfind("thick:", 0) == 0) {
    o.pass.thickness = static_cast<float>(ParseNumbers(cut.substr(6), "--cut thick:T").at(0));
    cut = "thick";
  }
  o.pass.cut = core::CutModeFromName(cut);
  if (!f.region.empty()) {
    std::vector<double> r = ParseNumbers(f.region, "--region");
    if (r.size() != 6) core::ThrowInputError("ibr deform", "--region needs x0,y0,z0,x1,y1,z1");
    o.region = core::Box3d{{r[0], r[1], r[2]}, {r[3], r[4], r[5]}};
  }
  if (!f.placement.empty()) {
    std::vector<double> p = ParseNumbers(f.placement, "--placement");
    if (p.size() != 3 && p.size() != 6 && p.size() != 7) {
      core::ThrowInputError("ibr deform", "--placement needs tx,ty,tz[,rx,ry,rz[,scale]]");
    }
    o.translation = {p[0], p[1], p[2]};
    if (p.size() >= 6) o.rotation_deg = {p[3], p[4], p[5]};
    if (p.size() == 7) o.scale = p[6];
  }
  std::string step = f.step;
  if (step.rfind("threshold:", 0) == 0) {
    o.pass.threshold =
        static_cast<float>(ParseNumbers(step.substr(10), "--step threshold:T").at(0));
    step = "threshold";
  }
  o.pass.step_policy = render::RayStepPolicyFromName(step);
  if (f.implicit != "sdf") {
    core::ThrowInputError(
        "ibr deform", "--implicit {}: only 'sdf' is implemented (depth-cube is not)", f.implicit);
  }
  o.pass.step_voxels = f.step_voxels;
  o.pass.skip_empty = f.skip;
  o.sdf_resolution = f.resolution;
  o.size = f.size;
  o.azimuth_deg = f.azimuth;
  o.elevation_deg = f.elevation;
  o.cameras = f.cameras;
  o.out = f.out;
  auto context = render::HeadlessContext::Create();
  render::ProgramCache programs;
  // Checks the options and every frame size (--size, --cameras' views) first.
  const bench::DeformRunReport r = bench::RunDeform(programs, o);
  fmt::print(
      "deform: distance field {}x{}x{} in {:.2f} s ({} exact distance queries), max displacement "
      "{:.4f}\n",
      r.sdf_size.x, r.sdf_size.y, r.sdf_size.z, r.sdf_seconds, r.distance_queries,
      r.max_displacement);
  auto print = [](const std::string& what, const bench::DeformOutcomes& c) {
    fmt::print(
        "deform: {}: pixels mesh {} ray-hit {} cut-face {} exited {} early-termination {}; {} "
        "rays, "
        "{:.1f} samples per ray\n",
        what, c.mesh_pixels, c.hit_pixels, c.cut_face_pixels, c.exited_pixels, c.early_pixels,
        c.rays, c.mean_samples);
  };
  for (const bench::DeformViewReport& v : r.views) print("view " + v.name, v.outcomes);
  if (r.views.size() > 1) print(fmt::format("all {} views", r.views.size()), r.total);
  fmt::print("deform: {:.1f} ms per frame (first view); wrote {}\n", r.frame_ms, f.out);
}

void AddDeformCommand(CLI::App& app) {
  static DeformFlags f;
  auto* cmd = app.add_subcommand(
      "deform", "Render a mesh deformed and cut in the pixel shader (Correa 2007)");
  cmd->add_option("mesh", f.mesh, "mesh file (OBJ/PLY/...), normalised to the unit cube")
      ->required();
  cmd->add_flag("--cap-holes", f.cap_holes, "fill the boundary loops of an open mesh");
  cmd->add_option("--deformation", f.deformations, "twist|bend|pull|knife|peel (repeat to sum)")
      ->delimiter(',');
  cmd->add_option("--amount", f.amounts,
                  "per deformation: twist/bend/peel angle (rad), pull amplitude, knife opening")
      ->delimiter(',');
  cmd->add_option("--width", f.widths,
                  "per deformation: twist rigid radius, pull sigma, knife depth, peel thickness "
                  "(box units)")
      ->delimiter(',');
  cmd->add_option("--cut", f.cut, "none|hollow|solid|thick:T")->capture_default_str();
  cmd->add_option("--region", f.region,
                  "x0,y0,z0,x1,y1,z1 (normalised units; default: mesh bounds + 0.05)");
  cmd->add_option("--placement", f.placement,
                  "tx,ty,tz[,rx,ry,rz[,scale]] about the region's centre");
  cmd->add_option("--step", f.step, "fixed|threshold:T|jacobian")->capture_default_str();
  cmd->add_option("--step-voxels", f.step_voxels, "base step in distance-field voxels")
      ->capture_default_str();
  cmd->add_flag("--skip", f.skip, "empty-space skipping in the cut (sec. 6.2)");
  cmd->add_option("--implicit", f.implicit, "sdf (depth-cube: not implemented)")
      ->capture_default_str();
  cmd->add_option("--resolution", f.resolution, "distance-field samples along the longest axis")
      ->capture_default_str();
  cmd->add_option("--size", f.size, "image width = height in pixels")->capture_default_str();
  cmd->add_option("--azimuth", f.azimuth, "degrees about +y")->capture_default_str();
  cmd->add_option("--elevation", f.elevation, "degrees above the horizon")->capture_default_str();
  cmd->add_option("--cameras", f.cameras,
                  "render from this dataset's cameras (world = the mesh file's frame)");
  cmd->add_option("--out", f.out,
                  "FILE.png (colour; camera-z EXR beside it) or DIR (a dataset folder as ibr "
                  "render writes)")
      ->required();
  cmd->callback([] { RunDeformCommand(f); });
}

}  // namespace

IBR_REGISTER_COMMAND("deform", AddDeformCommand);

}  // namespace apps
