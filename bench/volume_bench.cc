#include "bench/volume_bench.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <utility>

#include "bench/gallery.h"
#include "bench/report.h"
#include "bench/sweep.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/image_compose.h"
#include "core/metrics.h"
#include "core/volume_displacement.h"
#include "core/volume_io.h"
#include "ibr/jobs/volume_job.h"
#include "render/gl/fill_rate.h"
#include "render/gl/frame_timer.h"

namespace bench {
namespace {
namespace fs = std::filesystem;

struct Measured {
  double ms = 0;
  int64_t jacobian_bytes = 0;    // the maps' J_D / grad alpha textures (0 when not read)
  double area_px = 0;            // rasterised slice area per frame
  double displaced_area_px = 0;  // the part drawn by the displaced shader
  int slices = 0;
  int map_bits = 0;       // the maps' storage (0: no maps)
  int64_t map_bytes = 0;  // their (D, alpha) textures as uploaded
  core::ImageF color;     // float RGBA of the view, when asked for (TimeVolume's `float_image`)
};

// The bench's one view of a volume: azimuth 30, elevation 20 degrees.
render::ViewSetup BenchView(const ibr::VolumeObjectData& scene, int size) {
  return ibr::VolumeOrbitView(30, 20, 3.2 * scene.radius, size, scene.radius);
}

Measured TimeVolume(render::ProgramCache& programs, const ibr::VolumeObjectData& scene,
                    const render::VolumePassOptions& options, int size,
                    const render::FrameTimerOptions& timer, bool float_image = false) {
  render::VolumePass pass(programs, scene.volume, scene.transfer, scene.maps,
                          scene.world_from_volume, options);
  const render::ViewSetup view = BenchView(scene, size);
  render::RenderTarget target(render::FrameTargetOptions(size, size));
  Measured m;
  m.ms = render::TimeFrames(
             [&] {
               render::BeginFrame(target);
               pass.Draw(target, view);
             },
             timer)
             .median_ms;
  m.area_px = pass.last_stats().proxy_area_px;
  m.displaced_area_px = pass.last_stats().displaced_area_px;
  m.slices = pass.last_stats().slices;
  m.map_bits = scene.maps.empty() ? 0 : options.displacement_bits;
  m.map_bytes = pass.map_texture_bytes();
  m.jacobian_bytes = pass.derivative_texture_bytes();
  if (!scene.maps.empty()) {
    spdlog::info(
        "bench volume: displaced shader on {:.1f}% of the slice area, {:.1f}% cut away (not "
        "drawn), {} parts, {} draw calls",
        100 * pass.last_stats().displaced_area_px / std::max(m.area_px, 1.0),
        100 * pass.last_stats().cut_area_px / std::max(m.area_px, 1.0), pass.last_stats().parts,
        pass.last_stats().draw_calls);
  }
  // The same pass, after timing, into a float target: no second build or upload.
  if (float_image) m.color = ibr::DrawVolumeFloat(pass, BenchView(scene, size), size);
  for (const core::Box3& b : pass.active_boxes()) {
    const glm::dvec3 e = glm::max(b.hi - b.lo, glm::dvec3(0.0));
    spdlog::info(
        "bench volume: a map's active box [{:.2f} {:.2f} {:.2f}]-[{:.2f} {:.2f} {:.2f}], "
        "{:.0f}% of its cube",
        b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z, 100 * e.x * e.y * e.z);
  }
  return m;
}

// A 256^3 synthetic volume: nested shells (uint8), the "large" row.
core::Volume SyntheticVolume(int n) {
  core::Volume v = core::Volume::Zeros({n, n, n}, core::ScalarType::kUint8);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const double r =
            glm::length(glm::dvec3(x + 0.5, y + 0.5, z + 0.5) / static_cast<double>(n) - 0.5);
        v.SetValue(x, y, z, r < 0.45 ? 255 * (0.5 + 0.5 * std::cos(r * 40)) : 0);
      }
  return v;
}

struct PeerResult {
  bool ok = false;
  double median_ms = 0, min_ms = 0, first_s = 0;
  double resample_ms = std::nan("");  // "vtk prewarped": the CPU warp of the volume
  glm::ivec3 warped_dims{0};          // its output grid (the proxy box at voxel spacing)
  std::string error;
};

// The volume warped by a map for the "vtk prewarped" peer: the map as the
// pass reads it (stored at `bits`, dequantised), its axis-aligned placement
// and the pass's proxy box (volume texture space), and where the peer writes
// its warped volume (float32, normalised) for CheckPrewarp.
struct WarpInput {
  core::DisplacementMap map;
  glm::dmat4 placement{1.0};
  core::Box3 proxy;
  fs::path out_raw;
};

// Writes the map and the peer's warp JSON into `work`; returns the JSON's path.
fs::path WriteWarpInput(const WarpInput& w, const std::string& stem, const fs::path& work) {
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      if (a != b && w.placement[a][b] != 0)
        core::ThrowInputError("ibr bench volume", "the VTK peer needs an axis-aligned placement");
  const fs::path raw = work / (stem + ".map.raw"), json_path = work / (stem + ".warp.json");
  core::AtomicWriteStream(raw, [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(w.map.texels.data()),
              static_cast<std::streamsize>(w.map.texels.size() * sizeof(glm::vec4)));
  });
  const glm::dvec3 lo(w.placement[3]);
  const glm::dvec3 scale(w.placement[0][0], w.placement[1][1], w.placement[2][2]);
  nlohmann::json j;
  j["map_raw"] = raw.string();
  j["map_dims"] = {w.map.dims.x, w.map.dims.y, w.map.dims.z};
  j["placement_lo"] = {lo.x, lo.y, lo.z};
  j["placement_scale"] = {scale.x, scale.y, scale.z};
  j["proxy_lo"] = {w.proxy.lo.x, w.proxy.lo.y, w.proxy.lo.z};
  j["proxy_hi"] = {w.proxy.hi.x, w.proxy.hi.y, w.proxy.hi.z};
  j["out_raw"] = w.out_raw.string();
  core::AtomicWriteStream(json_path, [&](std::ostream& out) { out << j.dump(); });
  return json_path;
}

PeerResult RunVtkPeer(const fs::path& dat, int size, double sample,
                      const core::TransferFunction& tf, const fs::path& work,
                      const WarpInput* warp = nullptr) {
  PeerResult r;
  const fs::path tf_path = work / (dat.stem().string() + ".tf.json");
  nlohmann::json j;
  j["points"] = nlohmann::json::array();
  for (const auto& p : tf.points)
    j["points"].push_back({p.s, p.rgba.r, p.rgba.g, p.rgba.b, p.rgba.a});
  core::AtomicWriteStream(tf_path, [&](std::ostream& out) { out << j.dump(); });
  const fs::path script = fs::path(IBR_BENCH_SOURCE_DIR) / "vtk_volume_peer.py";
  const fs::path warp_json = warp ? WriteWarpInput(*warp, dat.stem().string(), work) : fs::path();
  const std::string warp_arg = warp ? fmt::format(" '{}'", warp_json.string()) : "";
  // The peer's inputs are scratch, not results: gone when it returns.
  const auto remove_inputs = [&] {
    fs::remove(tf_path);
    if (!warp) return;
    fs::remove(warp_json);
    fs::remove(fs::path(warp_json).replace_extension("").replace_extension(".map.raw"));
  };
  const std::string cmd =
      fmt::format("xvfb-run -a /usr/bin/python3 '{}' '{}' {} {} '{}' 12{} 2>&1", script.string(),
                  dat.string(), size, sample, tf_path.string(), warp_arg);
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(cmd.c_str(), "r"), pclose);
  if (!pipe) {
    remove_inputs();
    r.error = "cannot start xvfb-run";
    return r;
  }
  std::string output;
  std::array<char, 4096> buf{};
  while (fgets(buf.data(), buf.size(), pipe.get())) output += buf.data();
  pipe.reset();  // waits for the peer
  remove_inputs();
  const size_t brace = output.rfind("{\"first_frame_s\"");
  if (brace == std::string::npos) {
    r.error = output.substr(0, 300);
    return r;
  }
  try {
    const auto res = nlohmann::json::parse(output.substr(brace, output.find('\n', brace) - brace));
    r.median_ms = res["median_ms"].get<double>();
    r.min_ms = res["min_ms"].get<double>();
    r.first_s = res["first_frame_s"].get<double>();
    if (warp) {
      r.resample_ms = res["resample_ms"].get<double>();
      const auto dims = res["warped_voxels"].get<std::vector<int>>();
      if (dims.size() == 3) r.warped_dims = {dims[0], dims[1], dims[2]};
    }
    r.ok = true;
  } catch (const std::exception& e) {
    r.error = e.what();
  }
  return r;
}

// A volume of the bench: a shared QVis pair, or the synthetic one.
struct Entry {
  std::string name;
  fs::path dat;  // empty for the synthetic volume
};

// The QVis pair the peer reads: the entry's own, or the synthetic volume
// written into the work folder (RemovePeerDat removes it).
fs::path PeerDat(const Entry& e, const core::Volume& volume, const fs::path& work) {
  if (!e.dat.empty()) return e.dat;
  const fs::path dat = work / (e.name + ".dat");
  core::WriteQVis(dat, volume);
  return dat;
}

void RemovePeerDat(const Entry& e, const fs::path& dat) {
  if (!e.dat.empty()) return;
  fs::remove(dat);
  fs::remove(fs::path(dat).replace_extension(".raw"));
}

// p95 of |peer's warped scalar - ours| (normalised units) over 4096 random
// voxels of the peer's warped grid where either is not empty (most of a
// warped box is empty: a p95 over all voxels would hide the material): ours is core::Displace
// through the same map (read on its cube, eq. 10), the volume sampled trilinearly there, 0 where
// the mask is < 0.5. NaN when the peer's file is missing or short.
double CheckPrewarp(const core::Volume& volume, const WarpInput& w, const glm::ivec3& dims) {
  const size_t count = static_cast<size_t>(dims.x) * dims.y * dims.z;
  std::ifstream in(w.out_raw, std::ios::binary);
  std::vector<float> warped(count);
  if (count == 0 || !in.read(reinterpret_cast<char*>(warped.data()),
                             static_cast<std::streamsize>(count * sizeof(float))))
    return std::nan("");
  const core::PlacedMap placed{&w.map, w.placement, core::Box3{}};
  std::vector<double> errors;
  std::mt19937_64 rng(35);  // deterministic voxels spread over the grid
  std::uniform_int_distribution<size_t> pick(0, count - 1);
  for (int k = 0; k < 4096; ++k) {
    const size_t i = pick(rng);
    const glm::ivec3 v(static_cast<int>(i % dims.x), static_cast<int>(i / dims.x % dims.y),
                       static_cast<int>(i / (size_t(dims.x) * dims.y)));
    // The peer's voxel centres: the proxy box's corner plus half a voxel.
    const glm::dvec3 p_prime = w.proxy.lo + (glm::dvec3(v) + 0.5) / glm::dvec3(volume.dims);
    const core::DisplacedSample d = core::Displace({placed}, p_prime);
    // 0 outside the volume's box, as the pass's VolumeSample and VTK's background.
    const bool inside = glm::all(glm::greaterThanEqual(d.p, glm::dvec3(0.0))) &&
                        glm::all(glm::lessThanEqual(d.p, glm::dvec3(1.0)));
    const double ours = d.alpha >= 0.5 && inside ? core::SampleTrilinear(volume, d.p) : 0.0;
    if (ours > 0 || warped[i] > 0) errors.push_back(std::abs(ours - warped[i]));
  }
  if (errors.empty()) return std::nan("");
  std::sort(errors.begin(), errors.end());
  return errors[static_cast<size_t>(0.95 * static_cast<double>(errors.size() - 1))];
}

}  // namespace

std::vector<std::string> VolumeBenchColumns() {
  return {"sweep",
          "volume",
          "variant",
          "sampling_voxels",
          "map_size",
          "map_bits",
          "bytes_per_map",
          "jacobian_bytes",
          "size_px",
          "slices",
          "ms_per_frame",
          "area_Mpx",
          "ns_per_fragment",
          "fill_fraction",
          "map_coverage",
          "ratio_to_plain",
          "vtk_ms",
          "vtk_min_ms",
          "vtk_resample_ms",
          "vtk_warp_p95_error",
          "p95_color_error_vs_finest",
          "p95_color_error_vs_32bit",
          "max_color_error_vs_32bit"};
}

Table VolumeGoalsTable(const Table& v) {
  // Per volume (in the order measured): the figures the goals read.
  std::vector<std::string> order;
  std::map<std::string, std::map<std::string, double>> f;
  const int sweep = v.Column("sweep"), volume = v.Column("volume"), variant = v.Column("variant");
  const auto cell = [&](const std::vector<std::string>& r, const char* column) {
    return CellNumber(r[v.Column(column)]);
  };
  for (const auto& r : v.rows()) {
    const std::string& name = r[volume];
    const std::string key = r[sweep] + "/" + r[variant];
    auto& g = f[name];
    if (key == "volume/plain DVR (shaded)") {
      order.push_back(name);
      g["plain"] = cell(r, "ms_per_frame");
      g["plain_ns"] = cell(r, "ns_per_fragment");
    } else if (key == "volume/peel 64^3 (eq. 6+7)") {
      g["peel"] = cell(r, "ms_per_frame");
      g["coverage"] = cell(r, "map_coverage");
    } else if (key == "unsplit/peel 64^3 (eq. 6+7) unsplit") {
      g["unsplit"] = cell(r, "ms_per_frame");
      g["unsplit_ns"] = cell(r, "ns_per_fragment");
    } else if (key == "floor/displaced floor") {
      g["floor"] = cell(r, "ms_per_frame");
    } else if (key == "peer/vtk prewarped") {
      g["vtk"] = cell(r, "ms_per_frame");
      g["resample"] = cell(r, "vtk_resample_ms");
      g["check"] = cell(r, "vtk_warp_p95_error");
    }
  }
  // "tooth 1.52, neghip 1.71" of one figure over the volumes, and whether
  // every one is finite and within `goal` (NaN: no goal).
  struct Listed {
    std::string text;
    std::string met;
  };
  const auto list = [&](const std::function<double(std::map<std::string, double>&)>& figure,
                        double goal, const std::function<std::string(double)>& format) {
    Listed l;
    bool all = true, any = false;
    for (const std::string& name : order) {
      const double x = figure(f[name]);
      if (!std::isfinite(x)) continue;
      any = true;
      all = all && x <= goal;
      l.text += (l.text.empty() ? "" : ", ") + name + " " + format(x);
    }
    if (!any) l.text = "n/a";
    l.met = !any ? "n/a" : std::isnan(goal) ? "-" : all ? "yes" : "no";
    return l;
  };
  const auto ratio = [](double x) { return fmt::format("{:.2f}x", x); };
  const auto get = [](std::map<std::string, double>& g, const char* k) {
    return g.count(k) ? g[k] : std::nan("");
  };
  const double none = std::nan("");
  Table t({"quantity", "goal", "measured", "met", "note"});
  const auto row = [&](const std::string& q, const std::string& goal, const Listed& l,
                       const std::string& note) {
    t.AddRow({q, goal, l.text, l.met, note});
  };
  row("eq. 6+7 frame / displaced floor frame", "<= 2",
      list([&](auto& g) { return get(g, "peel") / get(g, "floor"); }, 2.0, ratio),
      "the peel (64^3 map, blended normals, split slices) over a map fetch and the scalar where "
      "it points on every fragment of the same slices; unsplit: " +
          list([&](auto& g) { return get(g, "unsplit") / get(g, "floor"); }, none, ratio).text);
  row("unsplit displaced / plain DVR, per fragment", "<= 2.5",
      list([&](auto& g) { return get(g, "unsplit_ns") / get(g, "plain_ns"); }, 2.5, ratio),
      "ns per rasterised slice fragment, every fragment displaced (eq. 6+7) against plain shaded "
      "DVR");
  row("displaced / plain DVR, per frame, at the map's coverage", "stated",
      list([&](auto& g) { return get(g, "peel") / get(g, "plain"); }, none,
           [](double x) { return fmt::format("{:.2f}x", x); }),
      "coverage (share of the slice area the displaced shader draws): " +
          list([&](auto& g) { return 100 * get(g, "coverage"); }, none,
               [](double x) { return fmt::format("{:.0f} %", x); })
              .text);
  row("ours displaced frame / VTK prewarped frame", "<= 1",
      list([&](auto& g) { return get(g, "peel") / get(g, "vtk"); }, 1.0, ratio),
      "VTK's GPU ray caster on the volume warped by the same map, same transfer function, "
      "sampling and image size, its own orbit of views");
  row("VTK's resample of the volume through D (the edit latency this method avoids)", "stated",
      list([&](auto& g) { return get(g, "resample"); }, none,
           [](double x) { return fmt::format("{:.0f} ms", x); }),
      "vtkGridTransform + vtkImageReslice onto the proxy box; its warped volume against ours, "
      "p95 (1/255): " +
          list([&](auto& g) { return get(g, "check"); }, none,
               [](double x) { return fmt::format("{:.2f}", x); })
              .text);
  return t;
}

void VolumeBenchOptions::Check() const {
  if (csv.empty()) core::ThrowInputError("ibr bench volume", "--csv FILE is required");
  if (size < 32 || size > 4096)
    core::ThrowInputError("ibr bench volume", "--size {} not in [32, 4096]", size);
}

namespace {

// ------------------------------------------------------------- the sweep ----

// Plain DVR, shaded as the peer shades: the frame every ratio is against.
render::VolumePassOptions PlainOptions() {
  render::VolumePassOptions plain;
  plain.lighting = render::VolumeLighting::kGradient;  // shading on, as the peer
  return plain;
}

// The peel through its map with blended normals (eq. 6+7): the "volume" row
// and the setting the other sweeps vary.
render::VolumePassOptions DisplacedOptions() {
  render::VolumePassOptions displaced = PlainOptions();
  displaced.lighting = render::VolumeLighting::kBlended;
  return displaced;
}

// The three shared volumes and, in the full sweep, the synthetic 256^3.
std::vector<Entry> VolumeEntries(const VolumeBenchOptions& o) {
  std::vector<Entry> volumes = {{"tooth", o.shared_data / "volumes/tooth_103x94x161_uint8.dat"},
                                {"neghip", o.shared_data / "volumes/neghip_64x64x64_uint8.dat"},
                                {"bucky", o.shared_data / "volumes/Bucky_32x32x32_uint8.dat"}};
  if (!o.quick) volumes.push_back({"synthetic256", {}});
  return volumes;
}

// What every row shares: the timer, the programs, the fill rate every
// fill_fraction is against, the pass settings, the table and the summary.
struct VolumeRun {
  explicit VolumeRun(const VolumeBenchOptions& o)
      : options(o), size(o.quick ? 128 : o.size), timer{1, o.quick ? 1 : 3} {}
  const VolumeBenchOptions& options;
  const int size;  // image size, pixels
  const render::FrameTimerOptions timer;
  render::ProgramCache programs;
  render::FillRateOptions fill_options;  // the calibration's (Calibrate)
  render::FillRate fill;
  fs::path work;  // where the peer's files go
  // The top layer z in [0.6, 0.8], x > 0.5, turned by 160 degrees.
  const std::vector<core::Deformation> peel = {
      {.kind = core::DeformationKind::kPeel, .amount = 160 * M_PI / 180, .width = 0.2}};
  const render::VolumePassOptions plain = PlainOptions(), displaced = DisplacedOptions();
  Table table{VolumeBenchColumns()};
  std::vector<std::string> summary;  // one line per volume: the ratios
};

// A row from named cells; the others empty.
void AddCells(Table& table, const std::map<std::string, std::string>& cells) {
  std::vector<std::string> row(table.columns().size());
  for (const auto& [column, value] : cells) row[table.Column(column)] = value;
  table.AddRow(std::move(row));
}

// A measured row and its progress line. `plain_ms`: the plain frame of the
// ratio (0: none); `error`: the p95 colour error against the finest setting
// (1/255; NaN: not measured, an empty cell); `vs_32bit` against the 32-bit
// map's.
void AddMeasured(VolumeRun& run, const std::string& sweep, const std::string& volume,
                 const std::string& variant, double sampling, int map_size, int px,
                 const Measured& m, double plain_ms, const PeerResult* peer, double error,
                 const core::ErrorStats* vs_32bit = nullptr) {
  const double fraction = m.area_px / (m.ms * 1e-3) / run.fill.fragments_per_second;
  const auto maybe = [](double v, int digits) { return std::isfinite(v) ? Num(v, digits) : ""; };
  AddCells(run.table, {{"sweep", sweep},
                       {"volume", volume},
                       {"variant", variant},
                       {"sampling_voxels", Num(sampling, 2)},
                       {"map_size", std::to_string(map_size)},
                       {"map_bits", m.map_bits ? std::to_string(m.map_bits) : ""},
                       {"bytes_per_map", m.map_bits ? std::to_string(m.map_bytes) : ""},
                       {"jacobian_bytes", m.map_bits ? std::to_string(m.jacobian_bytes) : ""},
                       {"size_px", std::to_string(px)},
                       {"slices", std::to_string(m.slices)},
                       {"ms_per_frame", Num(m.ms, 1)},
                       {"area_Mpx", Num(m.area_px * 1e-6, 3)},
                       {"ns_per_fragment", Num(m.ms * 1e6 / std::max(m.area_px, 1.0), 2)},
                       {"fill_fraction", Num(fraction, 3)},
                       {"map_coverage",
                        m.map_bits ? Num(m.displaced_area_px / std::max(m.area_px, 1.0), 3) : ""},
                       {"ratio_to_plain", plain_ms > 0 ? Num(m.ms / plain_ms, 2) : ""},
                       {"vtk_ms", peer && peer->ok ? Num(peer->median_ms, 1) : ""},
                       {"vtk_min_ms", peer && peer->ok ? Num(peer->min_ms, 1) : ""},
                       {"p95_color_error_vs_finest", maybe(error, 3)},
                       {"p95_color_error_vs_32bit", vs_32bit ? Num(vs_32bit->p95, 3) : ""},
                       {"max_color_error_vs_32bit", vs_32bit ? Num(vs_32bit->max, 3) : ""}});
  fmt::print("{:<10} {:<8} {:<22} {:>6.1f} ms  slices {:>4}  fill {:.3f}\n", sweep, volume, variant,
             m.ms, m.slices, fraction);
}

// The fill rate every fill_fraction is against: LINEAR, at the bench's size.
void Calibrate(VolumeRun& run) {
  run.fill_options.width = run.fill_options.height = run.size;
  run.fill_options.linear_filter = true;
  run.fill = render::MeasureFillRate(run.programs, run.fill_options);
  fmt::print("calibrated fill rate (LINEAR, {} px): {:.1f} M fragments/s\n", run.size,
             run.fill.fragments_per_second * 1e-6);
}

// The floors of a DVR fragment here, full-screen layers against the same
// calibration (what fill_fraction can reach at best on this machine): one
// trilinear 3D lookup classified by the transfer function, premultiplied
// blending (plain DVR), and a map's trilinear lookup before it, the volume
// read where it points (displaced DVR: the least a displaced sample does).
struct CalibrationFloor {
  render::FillRateOptions::Work work;
  std::string name;
};

std::vector<CalibrationFloor> CalibrationFloors() {
  using Work = render::FillRateOptions::Work;
  return {{Work::kVolumeBlend, "3D fetch + transfer function + blend"},
          {Work::kDisplacedVolumeBlend, "map fetch then 3D fetch + transfer function + blend"}};
}

void MeasureCalibrationFloor(VolumeRun& run, const CalibrationFloor& floor) {
  render::FillRateOptions floor_options = run.fill_options;
  floor_options.work = floor.work;
  const render::FillRate f = render::MeasureFillRate(run.programs, floor_options);
  const double fraction = f.fragments_per_second / run.fill.fragments_per_second;
  AddCells(run.table, {{"sweep", "floor"},
                       {"volume", "calibration"},
                       {"variant", floor.name},
                       {"sampling_voxels", "0"},
                       {"map_size", "0"},
                       {"size_px", std::to_string(run.size)},
                       {"slices", std::to_string(floor_options.layers_per_frame)},
                       {"ms_per_frame", Num(f.ms_per_frame, 1)},
                       {"area_Mpx", Num(f.fragments_per_frame * 1e-6, 3)},
                       {"ns_per_fragment", Num(1e9 / f.fragments_per_second, 2)},
                       {"fill_fraction", Num(fraction, 3)}});
  fmt::print("DVR floor ({}, {} px): {:.1f} M fragments/s, {:.3f} of the calibrated fill rate\n",
             floor.name, run.size, f.fragments_per_second * 1e-6, fraction);
}

// One volume of the sweep: the volume, its transfer function, the object
// bare and peeled (a 64^3 map), and what its other rows are read against:
// the plain peer's frame, the plain and the peeled frames.
struct VolumeCase {
  VolumeCase(const VolumeRun& run, const Entry& e)
      : entry(e),
        volume(e.dat.empty() ? SyntheticVolume(256) : core::ReadVolume(e.dat)),
        tf(ibr::TransferForVolume(e.dat.empty() ? "bucky" : "", e.dat)),
        bare(ibr::MakeVolumeObject(volume, tf, {}, 64)),
        peeled(ibr::MakeVolumeObject(volume, tf, run.peel, 64)) {}
  const Entry entry;
  const core::Volume volume;
  const core::TransferFunction tf;
  const ibr::VolumeObjectData bare, peeled;
  PeerResult peer;            // VTK on the plain volume (not ok: not run, or failed)
  Measured plain, displaced;  // the "volume" rows
};

// The VTK peer on the plain volume: same transfer function, sampling, size.
void RunPlainPeer(const VolumeRun& run, VolumeCase& c) {
  const fs::path dat = PeerDat(c.entry, c.volume, run.work);
  c.peer = RunVtkPeer(dat, run.size, 1.0, c.tf, run.work);
  RemovePeerDat(c.entry, dat);
  if (!c.peer.ok) spdlog::warn("VTK peer failed on {}: {}", c.entry.name, c.peer.error);
}

// The "volume" rows (plain, peel) and the floors on their own slices.
void MeasureFrames(VolumeRun& run, VolumeCase& c) {
  const std::string& name = c.entry.name;
  c.plain = TimeVolume(run.programs, c.bare, run.plain, run.size, run.timer);
  AddMeasured(run, "volume", name, "plain DVR (shaded)", 1.0, 0, run.size, c.plain, c.plain.ms,
              &c.peer, std::nan(""));
  c.displaced = TimeVolume(run.programs, c.peeled, run.displaced, run.size, run.timer);
  AddMeasured(run, "volume", name, "peel 64^3 (eq. 6+7)", 1.0, 64, run.size, c.displaced,
              c.plain.ms, nullptr, std::nan(""));
  // The floors on this frame's own slices (VolumePassOptions::floor_shader):
  // plain, one scalar fetch a fragment on the plain frame's slices; displaced,
  // a map fetch then the scalar where it points on every slice fragment of
  // the peeled frame (unsplit): the least a displaced frame can cost here.
  render::VolumePassOptions floor = run.plain;
  floor.lighting = render::VolumeLighting::kNone;
  floor.floor_shader = true;
  AddMeasured(run, "floor", name, "plain floor", 1.0, 0, run.size,
              TimeVolume(run.programs, c.bare, floor, run.size, run.timer), c.plain.ms, nullptr,
              std::nan(""));
  floor.support_skip = false;
  AddMeasured(run, "floor", name, "displaced floor", 1.0, 64, run.size,
              TimeVolume(run.programs, c.peeled, floor, run.size, run.timer), c.plain.ms, nullptr,
              std::nan(""));
}

// The peer warps the volume on the CPU by the same map, once, then ray
// casts the warped volume: what an edit of the map costs it (the resample)
// and what a frame costs it after.
void MeasurePrewarpedPeer(VolumeRun& run, const VolumeCase& c) {
  const std::string& name = c.entry.name;
  WarpInput warp{core::DequantizeDisplacementMap(core::StoreDisplacementMap(
                     c.peeled.maps[0].map, run.displaced.displacement_bits)),
                 c.peeled.maps[0].placement, render::VolumeProxyBox(c.peeled.maps),
                 run.work / (name + ".warped.raw")};
  const fs::path dat = PeerDat(c.entry, c.volume, run.work);
  const PeerResult warped = RunVtkPeer(dat, run.size, 1.0, c.tf, run.work, &warp);
  if (warped.ok) {
    const double check = CheckPrewarp(c.volume, warp, warped.warped_dims) * 255;
    AddCells(run.table, {{"sweep", "peer"},
                         {"volume", name},
                         {"variant", "vtk prewarped"},
                         {"sampling_voxels", Num(1.0, 2)},
                         {"map_size", "64"},
                         {"map_bits", std::to_string(run.displaced.displacement_bits)},
                         {"size_px", std::to_string(run.size)},
                         {"ms_per_frame", Num(warped.median_ms, 1)},
                         {"ratio_to_plain", Num(warped.median_ms / c.plain.ms, 2)},
                         {"vtk_ms", Num(warped.median_ms, 1)},
                         {"vtk_min_ms", Num(warped.min_ms, 1)},
                         {"vtk_resample_ms", Num(warped.resample_ms, 1)},
                         {"vtk_warp_p95_error", std::isfinite(check) ? Num(check, 3) : ""}});
    fmt::print(
        "vtk prewarped {:<8} resample {:.1f} ms (the edit latency), frame {:.1f} ms; ours "
        "displaced {:.1f} ms; warped volume vs ours p95 {:.3f}/255\n",
        name, warped.resample_ms, warped.median_ms, c.displaced.ms, check);
  } else {
    spdlog::warn("VTK prewarped peer failed on {}: {}", name, warped.error);
  }
  fs::remove(warp.out_raw);
  RemovePeerDat(c.entry, dat);
}

// A setting of the pass on the peeled object, named as its row's variant.
struct PassVariant {
  std::string variant;
  render::VolumePassOptions options;
};

// The "unsplit" sweep (its own sweep: the paper table reads every "volume"
// row as the peel), in the order of SummaryLine's `split_ms`.
std::vector<PassVariant> SplitVariants(const render::VolumePassOptions& displaced) {
  // The baseline of the support skip (VolumePassOptions::support_skip):
  // every slice fragment runs the displaced shader.
  render::VolumePassOptions unsplit = displaced;
  unsplit.support_skip = false;
  // The slices split at the support box only (no bricks,
  // VolumePassOptions::brick_texels 0): the split before bricks.
  render::VolumePassOptions box_only = displaced;
  box_only.brick_texels = 0;
  // Unsplit, the 16-bit map dequantised into an RGBA32F texture (the
  // upload before maps stayed 16-bit on the GPU).
  render::VolumePassOptions float_map = unsplit;
  float_map.float_map_textures = true;
  return {{"peel 64^3 (eq. 6+7) unsplit", unsplit},
          {"peel 64^3 (eq. 6+7) support box only", box_only},
          {"peel 64^3 (eq. 6+7) unsplit RGBA32F map", float_map}};
}

// The brick sizes of the split (VolumePassOptions::brick_texels) but the
// default, which is the "volume" row: finer bricks leave less area to the
// displaced shader but cut each slice into more parts.
std::vector<int> BrickSizes(const render::VolumePassOptions& displaced) {
  std::vector<int> sizes;
  for (const int bricks : {2, 3, 4, 8})
    if (bricks != displaced.brick_texels) sizes.push_back(bricks);
  return sizes;
}

// The peeled object's frame with `options`, a row of `sweep`; its ms.
double MeasurePeelVariant(VolumeRun& run, const VolumeCase& c, const std::string& sweep,
                          const PassVariant& v) {
  const Measured m = TimeVolume(run.programs, c.peeled, v.options, run.size, run.timer);
  AddMeasured(run, sweep, c.entry.name, v.variant, 1.0, 64, run.size, m, c.plain.ms, nullptr,
              std::nan(""));
  return m.ms;
}

PassVariant BrickVariant(const render::VolumePassOptions& displaced, int bricks) {
  render::VolumePassOptions by_bricks = displaced;
  by_bricks.brick_texels = bricks;
  return {fmt::format("peel 64^3 (eq. 6+7) bricks of {} texels", bricks), by_bricks};
}

// `split_ms`: the SplitVariants' frames, in their order.
std::string SummaryLine(const VolumeCase& c, const std::vector<double>& split_ms) {
  const double p = c.plain.ms, unsplit = split_ms[0], box_only = split_ms[1],
               float_map = split_ms[2];
  return fmt::format(
      "{:<13} plain {:7.1f} ms  peel {:7.1f} ms  peel/plain {:5.2f}x (support box only "
      "{:5.2f}x, unsplit {:5.2f}x, unsplit RGBA32F map {:5.2f}x)  VTK {}  plain/VTK {}",
      c.entry.name, p, c.displaced.ms, c.displaced.ms / p, box_only / p, unsplit / p, float_map / p,
      c.peer.ok ? fmt::format("{:7.1f} ms", c.peer.median_ms) : "  n/a",
      c.peer.ok ? fmt::format("{:5.2f}x", p / c.peer.median_ms) : "n/a");
}

// Where the time goes (same volume, view and slices; names without commas,
// the CSV is not quoted): the per-draw overhead, the fill-rate floor's work
// on these slices (against the floor rows' full-screen layers), the shading,
// the map lookup alone, eq. 6 without / with eq. 7, and J_D per sample
// instead of per texel.
struct Profile {
  const char* variant;
  bool displaced;
  render::VolumeLighting lighting;
  render::VolumeJacobian jacobian;
  bool per_slice;
  bool support_skip = true;
  int bits = 16;              // the map's storage
  bool float_maps = false;    // its texture: UNORM, or dequantised RGBA32F
  bool floor_shader = false;  // VolumePassOptions::floor_shader
};

std::vector<Profile> ToothProfiles() {
  using L = render::VolumeLighting;
  using J = render::VolumeJacobian;
  return {
      {"plain unshaded", false, L::kNone, J::kPrecomputed, false},
      {"plain one draw per slice", false, L::kGradient, J::kPrecomputed, true},
      {"plain floor shader", false, L::kNone, J::kPrecomputed, false, true, 16, false, true},
      {"peel unshaded", true, L::kNone, J::kPrecomputed, false},
      {"peel unshaded unsplit", true, L::kNone, J::kPrecomputed, false, false},
      {"peel unshaded unsplit RGBA32F map", true, L::kNone, J::kPrecomputed, false, false, 16,
       true},
      {"peel unshaded unsplit RGBA8 map", true, L::kNone, J::kPrecomputed, false, false, 8, false},
      {"peel gradient only", true, L::kGradient, J::kPrecomputed, false},
      {"peel gradient only unsplit", true, L::kGradient, J::kPrecomputed, false, false},
      {"peel eq. 6", true, L::kTransformed, J::kPrecomputed, false},
      {"peel eq. 6 unsplit", true, L::kTransformed, J::kPrecomputed, false, false},
      {"peel eq. 6+7 one draw per part", true, L::kBlended, J::kPrecomputed, true},
      {"peel eq. 6+7 J_D differences", true, L::kBlended, J::kFiniteDifferences, false}};
}

void MeasureProfile(VolumeRun& run, const VolumeCase& c, const Profile& pr) {
  render::VolumePassOptions po = run.plain;
  po.lighting = pr.lighting;
  po.jacobian = pr.jacobian;
  po.draw_per_slice = pr.per_slice;
  po.support_skip = pr.support_skip;
  po.displacement_bits = pr.bits;
  po.float_map_textures = pr.float_maps;
  po.floor_shader = pr.floor_shader;
  AddMeasured(run, "profile", c.entry.name, pr.variant, 1.0, pr.displaced ? 64 : 0, run.size,
              TimeVolume(run.programs, pr.displaced ? c.peeled : c.bare, po, run.size, run.timer),
              c.plain.ms, nullptr, std::nan(""));
}

// The knobs' values swept on the tooth: sampling distances (voxels) and map
// sizes (texels per axis).
std::vector<double> SamplingDistances(const VolumeBenchOptions& o) {
  return o.quick ? std::vector<double>{0.5, 2.0} : std::vector<double>{0.5, 1.0, 2.0, 4.0};
}
std::vector<int> MapSizes(const VolumeBenchOptions& o) {
  return o.quick ? std::vector<int>{16, 64} : std::vector<int>{16, 32, 64, 128};
}

// One setting timed with its float image, and the image's p95 colour error
// against `truth` (1/255).
std::pair<Measured, double> TimeWithError(VolumeRun& run, const ibr::VolumeObjectData& scene,
                                          const render::VolumePassOptions& po,
                                          const core::ImageF& truth) {
  const Measured m = TimeVolume(run.programs, scene, po, run.size, run.timer, true);
  return {m, core::SummarizeErrors(ColorErrors(m.color, truth)).p95};
}

void MeasureSampling(VolumeRun& run, const VolumeCase& c, double sampling,
                     const core::ImageF& truth) {
  render::VolumePassOptions s = run.displaced;
  s.sampling_distance_voxels = sampling;
  const auto [m, error] = TimeWithError(run, c.peeled, s, truth);
  AddMeasured(run, "sampling", c.entry.name, "peel 64^3", sampling, 64, run.size, m, 0, nullptr,
              error);
}

void MeasureMapSize(VolumeRun& run, const VolumeCase& c, int map_size, const core::ImageF& truth) {
  const ibr::VolumeObjectData m = ibr::MakeVolumeObject(c.volume, c.tf, run.peel, map_size);
  const auto [measured, error] = TimeWithError(run, m, run.displaced, truth);
  AddMeasured(run, "map_size", c.entry.name, "peel", 1.0, map_size, run.size, measured, 0, nullptr,
              error);
}

// Correa 2006 Table 2 analogue: map size x stored bits -> the (D, alpha)
// texture's bytes as uploaded (8/16-bit maps stay UNORM on the GPU; the J_D
// textures are RGBA32F at any bits), time, and the picture's colour error
// against the same map stored in 32 bits.
void MeasureMapBits(VolumeRun& run, const VolumeCase& c, int map_size) {
  const ibr::VolumeObjectData m = ibr::MakeVolumeObject(c.volume, c.tf, run.peel, map_size);
  render::VolumePassOptions by_bits = run.displaced;
  by_bits.displacement_bits = 32;
  const Measured full = TimeVolume(run.programs, m, by_bits, run.size, run.timer, true);
  const core::ErrorStats exact{};
  AddMeasured(run, "bits", c.entry.name, "peel 32-bit RGBA32F map", 1.0, map_size, run.size, full,
              0, nullptr, std::nan(""), &exact);
  for (const int bits : {16, 8}) {
    by_bits.displacement_bits = bits;
    const Measured q = TimeVolume(run.programs, m, by_bits, run.size, run.timer, true);
    const core::ErrorStats vs = core::SummarizeErrors(ColorErrors(q.color, full.color));
    AddMeasured(run, "bits", c.entry.name, fmt::format("peel {}-bit RGBA{} map", bits, bits), 1.0,
                map_size, run.size, q, 0, nullptr, std::nan(""), &vs);
  }
}

// What the two accuracy knobs cost: each setting's image (float colour, the
// bench's view) against the finest setting, map 128^3 sampled every 0.25
// voxel, itself timed as the family's truth; then the map's stored bits.
void MeasureAccuracy(VolumeRun& run, const VolumeCase& c) {
  const ibr::VolumeObjectData finest_map = ibr::MakeVolumeObject(c.volume, c.tf, run.peel, 128);
  render::VolumePassOptions finest = run.displaced;
  finest.sampling_distance_voxels = 0.25;
  const Measured reference =
      TimeVolume(run.programs, finest_map, finest, run.size, run.timer, true);
  AddMeasured(run, "finest", c.entry.name, "peel 128^3 at 0.25 voxel", 0.25, 128, run.size,
              reference, 0, nullptr, 0.0);
  // The sampling rows against the same 64^3 map sampled every 0.25 voxel:
  // against the 128^3 map their error would measure the map size as much
  // as the sampling.
  const core::ImageF sampling_truth =
      TimeVolume(run.programs, c.peeled, finest, run.size, run.timer, true).color;
  Sweep<double>(SamplingDistances(run.options), {}, [&](const double& sampling, int) {
    MeasureSampling(run, c, sampling, sampling_truth);
  });
  Sweep<int>(MapSizes(run.options), {},
             [&](const int& map_size, int) { MeasureMapSize(run, c, map_size, reference.color); });
  Sweep<int>(MapSizes(run.options), {},
             [&](const int& map_size, int) { MeasureMapBits(run, c, map_size); });
}

// Time against the rasterised proxy area: neghip's plain frame at image sizes.
std::vector<int> AreaSizes(const VolumeBenchOptions& o) {
  return o.quick ? std::vector<int>{64, 128} : std::vector<int>{128, 256, 384, 512};
}

void MeasureArea(VolumeRun& run, const VolumeCase& c, int px) {
  AddMeasured(run, "area", c.entry.name, "plain DVR (shaded)", 1.0, 0, px,
              TimeVolume(run.programs, c.bare, run.plain, px, run.timer), 0, nullptr, std::nan(""));
}

// Every row of one volume, in the order of the table.
void MeasureVolume(VolumeRun& run, const Entry& e) {
  VolumeCase c(run, e);
  spdlog::info("bench volume: {} ({} x {} x {})", e.name, c.volume.dims.x, c.volume.dims.y,
               c.volume.dims.z);
  if (run.options.peer) RunPlainPeer(run, c);
  MeasureFrames(run, c);
  if (run.options.peer) MeasurePrewarpedPeer(run, c);
  std::vector<double> split_ms;
  Sweep<PassVariant>(SplitVariants(run.displaced), {}, [&](const PassVariant& v, int) {
    split_ms.push_back(MeasurePeelVariant(run, c, "unsplit", v));
  });
  Sweep<int>(BrickSizes(run.displaced), {}, [&](const int& bricks, int) {
    MeasurePeelVariant(run, c, "bricks", BrickVariant(run.displaced, bricks));
  });
  run.summary.push_back(SummaryLine(c, split_ms));
  if (e.name == "tooth") {
    Sweep<Profile>(ToothProfiles(), {},
                   [&](const Profile& profile, int) { MeasureProfile(run, c, profile); });
    MeasureAccuracy(run, c);
  }
  if (e.name == "neghip") {
    Sweep<int>(AreaSizes(run.options), {}, [&](const int& px, int) { MeasureArea(run, c, px); });
  }
}

// R^2 of ms against area over the area sweep.
void PrintAreaFit(const Table& table) {
  std::vector<double> area_mpx, ms;
  for (const auto& row : table.rows()) {
    if (row[0] == "area") {
      area_mpx.push_back(std::stod(row[table.Column("area_Mpx")]));
      ms.push_back(std::stod(row[table.Column("ms_per_frame")]));
    }
  }
  if (area_mpx.size() < 2) return;
  const LineFit fit = FitLine(area_mpx, ms);
  // Degenerate data print NaN (FitLine reports 0, or r2 = 1 for constant times).
  auto spread = [](const std::vector<double>& v) {
    const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
    return *hi > *lo;
  };
  const bool x_spread = spread(area_mpx), y_spread = spread(ms);
  fmt::print("time vs rasterised proxy area (neghip, {} sizes): {:.3f} ms per M px, R^2 = {:.3f}\n",
             area_mpx.size(), x_spread ? fit.slope : std::nan(""),
             x_spread && y_spread ? fit.r2 : std::nan(""));
}

void PlotVolumeBench(const Table& table, const fs::path& out) {
  auto subset = [&](const std::string& sweep) {
    Table t(table.columns());
    for (const auto& row : table.rows())
      if (row[0] == sweep) t.AddRow(row);
    return t;
  };
  // Plain DVR: neghip at four image sizes and each volume at full size.
  Table plain_rows(table.columns());
  for (const auto& row : table.rows())
    if (row[0] == "area" || (row[0] == "volume" && row[2].rfind("plain", 0) == 0))
      plain_rows.AddRow(row);
  PlotPng(plain_rows,
          {.title = "volume: plain DVR time vs rasterised slice area",
           .x_column = "area_Mpx",
           .y_column = "ms_per_frame",
           .series_column = "volume",
           .x_label = "slice area (M pixels)",
           .y_label = "ms/frame"},
          out / "volume_time_vs_area.png");
  // The tooth's sweeps (Table 1-2 analogues), each on its own axis.
  PlotPng(subset("sampling"),
          {.title = "volume: peeled tooth, time vs sampling distance",
           .x_column = "sampling_voxels",
           .y_column = "ms_per_frame",
           .series_column = "variant",
           .x_label = "sampling distance (voxels)",
           .y_label = "ms/frame",
           .log_x = true},
          out / "volume_time_vs_sampling.png");
  PlotPng(subset("map_size"),
          {.title = "volume: peeled tooth, time vs displacement map size",
           .x_column = "map_size",
           .y_column = "ms_per_frame",
           .series_column = "variant",
           .x_label = "map texels per axis",
           .y_label = "ms/frame",
           .log_x = true},
          out / "volume_time_vs_map_size.png");
}

}  // namespace

Table RunVolumeBench(const VolumeBenchOptions& o) {
  o.Check();
  VolumeRun run(o);
  Calibrate(run);
  Sweep<CalibrationFloor>(CalibrationFloors(), {}, [&](const CalibrationFloor& floor, int) {
    MeasureCalibrationFloor(run, floor);
  });
  run.work = o.out.empty() ? fs::temp_directory_path() : o.out;
  if (!o.out.empty()) fs::create_directories(o.out);
  Sweep<Entry>(VolumeEntries(o), {}, [&](const Entry& e, int) { MeasureVolume(run, e); });
  PrintAreaFit(run.table);
  fmt::print("{}", run.table.Format());
  fmt::print("ratios at {} px, sampling distance 1 voxel (same run):\n", run.size);
  for (const std::string& line : run.summary) fmt::print("  {}\n", line);
  run.table.WriteCsv(o.csv);
  const Table goals = VolumeGoalsTable(run.table);
  fmt::print("{}", goals.Format());
  goals.WriteCsv(VolumeGoalsPath(o.csv));
  if (!o.out.empty()) PlotVolumeBench(run.table, o.out);
  return run.table;
}

}  // namespace bench
