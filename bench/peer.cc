#include "bench/peer.h"

#include <fmt/format.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "capture/synthetic.h"
#include "core/check.h"
#include "core/error.h"
#include "core/projection.h"
#include "core/timing.h"
#include "render/gl/gpu_mesh.h"
#include "render/passes/mesh_pass.h"

namespace bench {

std::string ShellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// ------------------------------------------------------------ metrics ----

double CubeEdge(const capture::Bounds& bounds) {
  const glm::dvec3 e = bounds.extent();
  return std::max({e.x, e.y, e.z});
}

std::vector<core::ImageF> RenderTruthDepth(render::ProgramCache& programs,
                                           const core::TriangleMesh& mesh,
                                           const std::vector<ibr::ViewCamera>& views,
                                           const capture::Bounds& bounds) {
  const render::GpuMesh gpu(mesh);
  std::vector<core::ImageF> out;
  for (const ibr::ViewCamera& v : views) {
    out.push_back(
        render::RenderMesh(programs, gpu, ViewSetupFor(v, bounds), v.camera.width, v.camera.height)
            .depth);
  }
  return out;
}

// --------------------------------------------------------------- rows ----

namespace {

// Renders every view (render_depth(i) returns view i's camera-z image), timed
// one by one: the first frame apart (time to first image), the median of the
// others; each view's depth compared with its truth.
template <typename RenderDepth>
void TimeViews(MethodRow& row, const std::vector<core::ImageF>& truth, double cube_edge,
               RenderDepth render_depth) {
  std::vector<double> frames;
  core::Stopwatch watch;
  for (size_t i = 0; i < truth.size(); ++i) {
    watch.Restart();
    const core::ImageF depth = render_depth(i);
    const double ms = watch.ElapsedMs();
    if (i == 0) {
      row.first_frame_ms = ms;
    } else {
      frames.push_back(ms);
    }
    row.per_view.push_back(CompareDepth(depth, truth[i], cube_edge));
  }
  row.median_frame_ms = frames.empty() ? row.first_frame_ms : core::Summarize(frames).median_ms;
}

}  // namespace

MethodRow EvaluateDepthObject(render::ProgramCache& programs, const ibr::MapSet& maps,
                              const ibr::DepthObjectOptions& options,
                              const std::vector<ibr::ViewCamera>& views,
                              const std::vector<core::ImageF>& truth, double cube_edge,
                              const std::string& label) {
  IBR_CHECK_EQ(views.size(), truth.size());
  IBR_CHECK(!views.empty());
  MethodRow row;
  row.method = label;
  core::Stopwatch watch;
  ibr::DepthObjectRenderer renderer(programs, maps);
  row.upload_ms = watch.ElapsedMs();
  TimeViews(row, truth, cube_edge,
            [&](size_t i) { return renderer.RenderFrame(views[i], options).depth; });
  row.time_to_first_image_s = (row.upload_ms + row.first_frame_ms) / 1000.0;
  row.accuracy = Pool(row.per_view);
  return row;
}

// ------------------------------------------------------------ Open3D ----

void Open3dPeerOptions::Check() const {
  constexpr const char* kWhere = "Open3dPeerOptions";
  if (python.empty()) core::ThrowInputError(kWhere, "python is empty");
  if (work_dir.empty())
    core::ThrowInputError(kWhere, "work_dir is required (meshes and peer.json go there)");
  if (methods.empty()) core::ThrowInputError(kWhere, "no methods");
  for (const std::string& m : methods) {
    const size_t colon = m.find(':');
    const std::string name = m.substr(0, colon);
    int n = 0;
    if (colon != std::string::npos) {
      try {
        n = std::stoi(m.substr(colon + 1));
      } catch (const std::exception&) {
        n = 0;
      }
    }
    if ((name != "tsdf" && name != "carve-depth" && name != "carve-silhouette") || n < 8 ||
        n > 1024) {
      core::ThrowInputError(
          kWhere, "method '{}' (tsdf:N, carve-depth:N, carve-silhouette:N, N in 8..1024)", m);
    }
  }
}

Open3dRun RunOpen3dPeer(const std::filesystem::path& dataset, const Open3dPeerOptions& options) {
  constexpr const char* kWhere = "RunOpen3dPeer";
  options.Check();
  const std::filesystem::path script =
      options.script.empty() ? std::filesystem::path(IBR_BENCH_SOURCE_DIR) / "open3d_peer.py"
                             : options.script;
  if (!std::filesystem::exists(script))
    core::ThrowInputError(kWhere, "'{}': no such script", script.string());
  std::filesystem::create_directories(options.work_dir);
  const std::filesystem::path report = options.work_dir / "peer.json";
  std::filesystem::remove(report);
  std::string methods;
  for (const std::string& m : options.methods) methods += (methods.empty() ? "" : ",") + m;
  const std::string command =
      fmt::format("{} {} {} --out {} --methods {} --orthographic {} 2>&1",
                  ShellQuote(options.python.string()), ShellQuote(script.string()),
                  ShellQuote(dataset.string()), ShellQuote(options.work_dir.string()),
                  ShellQuote(methods), options.far_pinhole ? "far-pinhole" : "skip");
  core::Stopwatch watch;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) core::ThrowInputError(kWhere, "cannot run '{}'", command);
  std::string output;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) output.append(buffer.data(), n);
  const int status = pclose(pipe);
  const double wall_s = watch.ElapsedMs() / 1000.0;
  if (status != 0 || !std::filesystem::exists(report)) {
    // The script's last line says what was wrong ("open3d_peer: ..."), or
    // Python's (ModuleNotFoundError: No module named 'open3d').
    std::string last = output;
    while (!last.empty() && last.back() == '\n') last.pop_back();
    last =
        last.substr(last.find_last_of('\n') == std::string::npos ? 0 : last.find_last_of('\n') + 1);
    core::ThrowInputError(kWhere, "{} on '{}' failed (exit status {}): {}",
                          script.filename().string(), dataset.string(),
                          WIFEXITED(status) ? WEXITSTATUS(status) : -1,
                          last.empty() ? std::string("no output") : last);
  }
  std::ifstream in(report);
  nlohmann::json j;
  try {
    in >> j;
    Open3dRun run;
    run.version = j.at("open3d").get<std::string>();
    run.views = j.at("views").get<int>();
    run.skipped_orthographic = j.at("skipped_orthographic").get<int>();
    run.import_s = j.at("import_s").get<double>();
    run.read_s = j.at("read_s").get<double>();
    run.wall_s = wall_s;
    for (const auto& r : j.at("results")) {
      Open3dResult res;
      res.method = r.at("method").get<std::string>();
      res.resolution = r.at("resolution").get<int>();
      res.voxel_size = r.at("voxel_size").get<double>();
      res.views_used = r.at("views_used").get<int>();
      res.integrate_s = r.at("integrate_s").get<double>();
      res.extract_s = r.at("extract_s").get<double>();
      res.triangles = r.at("triangles").get<int64_t>();
      const std::string mesh = r.at("mesh").get<std::string>();
      if (!mesh.empty()) res.mesh = mesh;
      run.results.push_back(res);
    }
    return run;
  } catch (const nlohmann::json::exception& e) {
    core::ThrowInputError(kWhere, "'{}': {}", report.string(), e.what());
  }
}

std::vector<MethodRow> EvaluatePeer(render::ProgramCache& programs, const Open3dRun& run,
                                    const std::vector<ibr::ViewCamera>& views,
                                    const std::vector<core::ImageF>& truth,
                                    const capture::Bounds& bounds, double cube_edge) {
  IBR_CHECK_EQ(views.size(), truth.size());
  IBR_CHECK(!views.empty());
  std::vector<MethodRow> rows;
  for (const Open3dResult& r : run.results) {
    MethodRow row;
    row.method = "open3d " + r.name();
    row.build_s = r.integrate_s + r.extract_s;
    row.triangles = r.triangles;
    if (r.mesh.empty()) {
      // Nothing survived: every view is empty.
      for (size_t i = 0; i < views.size(); ++i) {
        row.per_view.push_back(
            CompareDepth(core::ImageF(views[i].camera.width, views[i].camera.height, 1, 0.0f),
                         truth[i], cube_edge));
      }
    } else {
      const capture::SceneMesh scene = capture::LoadSceneMesh(r.mesh);
      core::Stopwatch watch;
      const render::GpuMesh gpu(scene.mesh);
      row.upload_ms = watch.ElapsedMs();
      TimeViews(row, truth, cube_edge, [&](size_t i) {
        return render::RenderMesh(programs, gpu, ViewSetupFor(views[i], bounds),
                                  views[i].camera.width, views[i].camera.height)
            .depth;
      });
    }
    row.time_to_first_image_s = row.build_s + (row.upload_ms + row.first_frame_ms) / 1000.0;
    row.accuracy = Pool(row.per_view);
    rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace bench
