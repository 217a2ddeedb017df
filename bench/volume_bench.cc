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
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/image_compose.h"
#include "core/metrics.h"
#include "core/volume_displacement.h"
#include "core/volume_io.h"
#include "ibr/volume_render.h"
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
  const std::string warp_arg =
      warp ? fmt::format(" '{}'", WriteWarpInput(*warp, dat.stem().string(), work).string()) : "";
  const std::string cmd =
      fmt::format("xvfb-run -a /usr/bin/python3 '{}' '{}' {} {} '{}' 12{} 2>&1", script.string(),
                  dat.string(), size, sample, tf_path.string(), warp_arg);
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(cmd.c_str(), "r"), pclose);
  if (!pipe) {
    r.error = "cannot start xvfb-run";
    return r;
  }
  std::string output;
  std::array<char, 4096> buf{};
  while (fgets(buf.data(), buf.size(), pipe.get())) output += buf.data();
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

Table RunVolumeBench(const VolumeBenchOptions& o) {
  o.Check();
  const int size = o.quick ? 128 : o.size;
  const render::FrameTimerOptions timer{1, o.quick ? 1 : 3};
  render::ProgramCache programs;
  render::FillRateOptions fill_options;
  fill_options.width = fill_options.height = size;
  fill_options.linear_filter = true;
  const render::FillRate fill = render::MeasureFillRate(programs, fill_options);
  fmt::print("calibrated fill rate (LINEAR, {} px): {:.1f} M fragments/s\n", size,
             fill.fragments_per_second * 1e-6);

  Table table(VolumeBenchColumns());
  // A row from named cells; the others empty.
  auto add_cells = [&](const std::map<std::string, std::string>& cells) {
    std::vector<std::string> row(table.columns().size());
    for (const auto& [column, value] : cells) row[table.Column(column)] = value;
    table.AddRow(std::move(row));
  };
  // `error`: the p95 colour error against the finest setting (1/255; NaN:
  // not measured, an empty cell); `vs_32bit` against the 32-bit map's.
  auto add = [&](const std::string& sweep, const std::string& volume, const std::string& variant,
                 double sampling, int map_size, int px, const Measured& m, double plain_ms,
                 const PeerResult* peer, double error, const core::ErrorStats* vs_32bit = nullptr) {
    const double fraction = m.area_px / (m.ms * 1e-3) / fill.fragments_per_second;
    const auto maybe = [](double v, int digits) { return std::isfinite(v) ? Num(v, digits) : ""; };
    add_cells(
        {{"sweep", sweep},
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
         {"map_coverage", m.map_bits ? Num(m.displaced_area_px / std::max(m.area_px, 1.0), 3) : ""},
         {"ratio_to_plain", plain_ms > 0 ? Num(m.ms / plain_ms, 2) : ""},
         {"vtk_ms", peer && peer->ok ? Num(peer->median_ms, 1) : ""},
         {"vtk_min_ms", peer && peer->ok ? Num(peer->min_ms, 1) : ""},
         {"p95_color_error_vs_finest", maybe(error, 3)},
         {"p95_color_error_vs_32bit", vs_32bit ? Num(vs_32bit->p95, 3) : ""},
         {"max_color_error_vs_32bit", vs_32bit ? Num(vs_32bit->max, 3) : ""}});
    fmt::print("{:<10} {:<8} {:<22} {:>6.1f} ms  slices {:>4}  fill {:.3f}\n", sweep, volume,
               variant, m.ms, m.slices, fraction);
  };
  // The floors of a DVR fragment here, full-screen layers against the same
  // calibration (what fill_fraction can reach at best on this machine): one
  // trilinear 3D lookup classified by the transfer function, premultiplied
  // blending (plain DVR), and a map's trilinear lookup before it, the volume
  // read where it points (displaced DVR: the least a displaced sample does).
  using Work = render::FillRateOptions::Work;
  for (const auto& [work, name] :
       {std::pair{Work::kVolumeBlend, "3D fetch + transfer function + blend"},
        std::pair{Work::kDisplacedVolumeBlend,
                  "map fetch then 3D fetch + transfer function + blend"}}) {
    render::FillRateOptions floor_options = fill_options;
    floor_options.work = work;
    const render::FillRate f = render::MeasureFillRate(programs, floor_options);
    const double fraction = f.fragments_per_second / fill.fragments_per_second;
    add_cells({{"sweep", "floor"},
               {"volume", "calibration"},
               {"variant", name},
               {"sampling_voxels", "0"},
               {"map_size", "0"},
               {"size_px", std::to_string(size)},
               {"slices", std::to_string(floor_options.layers_per_frame)},
               {"ms_per_frame", Num(f.ms_per_frame, 1)},
               {"area_Mpx", Num(f.fragments_per_frame * 1e-6, 3)},
               {"ns_per_fragment", Num(1e9 / f.fragments_per_second, 2)},
               {"fill_fraction", Num(fraction, 3)}});
    fmt::print("DVR floor ({}, {} px): {:.1f} M fragments/s, {:.3f} of the calibrated fill rate\n",
               name, size, f.fragments_per_second * 1e-6, fraction);
  }
  // The top layer z in [0.6, 0.8], x > 0.5, turned by 160 degrees.
  const std::vector<core::Deformation> peel = {
      {.kind = core::DeformationKind::kPeel, .amount = 160 * M_PI / 180, .width = 0.2}};
  render::VolumePassOptions plain;
  plain.lighting = render::VolumeLighting::kGradient;  // shading on, as the peer
  render::VolumePassOptions displaced = plain;
  displaced.lighting = render::VolumeLighting::kBlended;

  std::vector<Entry> volumes = {{"tooth", o.shared_data / "volumes/tooth_103x94x161_uint8.dat"},
                                {"neghip", o.shared_data / "volumes/neghip_64x64x64_uint8.dat"},
                                {"bucky", o.shared_data / "volumes/Bucky_32x32x32_uint8.dat"}};
  if (!o.quick) volumes.push_back({"synthetic256", {}});
  fs::path work = o.out.empty() ? fs::temp_directory_path() : o.out;
  if (!o.out.empty()) fs::create_directories(o.out);
  std::vector<std::string> summary;  // one line per volume: the ratios
  for (const Entry& e : volumes) {
    const core::Volume volume = e.dat.empty() ? SyntheticVolume(256) : core::ReadVolume(e.dat);
    const core::TransferFunction tf = ibr::TransferForVolume(e.dat.empty() ? "bucky" : "", e.dat);
    const ibr::VolumeObjectData bare = ibr::MakeVolumeObject(volume, tf, {}, 64);
    const ibr::VolumeObjectData peeled = ibr::MakeVolumeObject(volume, tf, peel, 64);
    spdlog::info("bench volume: {} ({} x {} x {})", e.name, volume.dims.x, volume.dims.y,
                 volume.dims.z);
    PeerResult peer;
    if (o.peer) {
      const fs::path dat = PeerDat(e, volume, work);
      peer = RunVtkPeer(dat, size, 1.0, tf, work);
      RemovePeerDat(e, dat);
      if (!peer.ok) spdlog::warn("VTK peer failed on {}: {}", e.name, peer.error);
    }
    const Measured p = TimeVolume(programs, bare, plain, size, timer);
    add("volume", e.name, "plain DVR (shaded)", 1.0, 0, size, p, p.ms, &peer, std::nan(""));
    const Measured d = TimeVolume(programs, peeled, displaced, size, timer);
    add("volume", e.name, "peel 64^3 (eq. 6+7)", 1.0, 64, size, d, p.ms, nullptr, std::nan(""));
    // The floors on this frame's own slices (VolumePassOptions::floor_shader):
    // plain, one scalar fetch a fragment on the plain frame's slices; displaced,
    // a map fetch then the scalar where it points on every slice fragment of
    // the peeled frame (unsplit): the least a displaced frame can cost here.
    render::VolumePassOptions floor = plain;
    floor.lighting = render::VolumeLighting::kNone;
    floor.floor_shader = true;
    add("floor", e.name, "plain floor", 1.0, 0, size,
        TimeVolume(programs, bare, floor, size, timer), p.ms, nullptr, std::nan(""));
    floor.support_skip = false;
    add("floor", e.name, "displaced floor", 1.0, 64, size,
        TimeVolume(programs, peeled, floor, size, timer), p.ms, nullptr, std::nan(""));
    if (o.peer) {
      // The peer warps the volume on the CPU by the same map, once, then ray
      // casts the warped volume: what an edit of the map costs it (the
      // resample) and what a frame costs it after.
      WarpInput warp{core::DequantizeDisplacementMap(core::StoreDisplacementMap(
                         peeled.maps[0].map, displaced.displacement_bits)),
                     peeled.maps[0].placement, render::VolumeProxyBox(peeled.maps),
                     work / (e.name + ".warped.raw")};
      const fs::path dat = PeerDat(e, volume, work);
      const PeerResult warped = RunVtkPeer(dat, size, 1.0, tf, work, &warp);
      if (warped.ok) {
        const double check = CheckPrewarp(volume, warp, warped.warped_dims) * 255;
        add_cells({{"sweep", "peer"},
                   {"volume", e.name},
                   {"variant", "vtk prewarped"},
                   {"sampling_voxels", Num(1.0, 2)},
                   {"map_size", "64"},
                   {"map_bits", std::to_string(displaced.displacement_bits)},
                   {"size_px", std::to_string(size)},
                   {"ms_per_frame", Num(warped.median_ms, 1)},
                   {"ratio_to_plain", Num(warped.median_ms / p.ms, 2)},
                   {"vtk_ms", Num(warped.median_ms, 1)},
                   {"vtk_min_ms", Num(warped.min_ms, 1)},
                   {"vtk_resample_ms", Num(warped.resample_ms, 1)},
                   {"vtk_warp_p95_error", std::isfinite(check) ? Num(check, 3) : ""}});
        fmt::print(
            "vtk prewarped {:<8} resample {:.1f} ms (the edit latency), frame {:.1f} ms; ours "
            "displaced {:.1f} ms; warped volume vs ours p95 {:.3f}/255\n",
            e.name, warped.resample_ms, warped.median_ms, d.ms, check);
      } else {
        spdlog::warn("VTK prewarped peer failed on {}: {}", e.name, warped.error);
      }
      fs::remove(warp.out_raw);
      RemovePeerDat(e, dat);
    }
    // The baseline of the support skip (VolumePassOptions::support_skip):
    // every slice fragment runs the displaced shader.
    render::VolumePassOptions unsplit = displaced;
    unsplit.support_skip = false;
    const Measured w = TimeVolume(programs, peeled, unsplit, size, timer);
    // (its own sweep: the paper table reads every "volume" row as the peel).
    add("unsplit", e.name, "peel 64^3 (eq. 6+7) unsplit", 1.0, 64, size, w, p.ms, nullptr,
        std::nan(""));
    // The slices split at the support box only (no bricks,
    // VolumePassOptions::brick_texels 0): the split before bricks.
    render::VolumePassOptions box_only = displaced;
    box_only.brick_texels = 0;
    const Measured x = TimeVolume(programs, peeled, box_only, size, timer);
    add("unsplit", e.name, "peel 64^3 (eq. 6+7) support box only", 1.0, 64, size, x, p.ms, nullptr,
        std::nan(""));
    // Unsplit, the 16-bit map dequantised into an RGBA32F texture (the
    // upload before maps stayed 16-bit on the GPU).
    unsplit.float_map_textures = true;
    const Measured b = TimeVolume(programs, peeled, unsplit, size, timer);
    add("unsplit", e.name, "peel 64^3 (eq. 6+7) unsplit RGBA32F map", 1.0, 64, size, b, p.ms,
        nullptr, std::nan(""));
    // The brick size of the split (VolumePassOptions::brick_texels; the
    // default is the "volume" row): finer bricks leave less area to the
    // displaced shader but cut each slice into more parts.
    for (const int bricks : {2, 3, 4, 8}) {
      if (bricks == displaced.brick_texels) continue;
      render::VolumePassOptions by_bricks = displaced;
      by_bricks.brick_texels = bricks;
      add("bricks", e.name, fmt::format("peel 64^3 (eq. 6+7) bricks of {} texels", bricks), 1.0, 64,
          size, TimeVolume(programs, peeled, by_bricks, size, timer), p.ms, nullptr, std::nan(""));
    }
    summary.push_back(fmt::format(
        "{:<13} plain {:7.1f} ms  peel {:7.1f} ms  peel/plain {:5.2f}x (support box only "
        "{:5.2f}x, unsplit {:5.2f}x, unsplit RGBA32F map {:5.2f}x)  VTK {}  plain/VTK {}",
        e.name, p.ms, d.ms, d.ms / p.ms, x.ms / p.ms, w.ms / p.ms, b.ms / p.ms,
        peer.ok ? fmt::format("{:7.1f} ms", peer.median_ms) : "  n/a",
        peer.ok ? fmt::format("{:5.2f}x", p.ms / peer.median_ms) : "n/a"));
    if (e.name == "tooth") {
      // Where the time goes (same volume, view and slices; names without
      // commas, the CSV is not quoted): the per-draw overhead, the
      // fill-rate floor's work on these slices (against the floor rows'
      // full-screen layers), the shading, the map lookup alone, eq. 6
      // without / with eq. 7, and J_D per sample instead of per texel.
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
      using L = render::VolumeLighting;
      using J = render::VolumeJacobian;
      for (const Profile& pr : std::vector<Profile>{
               {"plain unshaded", false, L::kNone, J::kPrecomputed, false},
               {"plain one draw per slice", false, L::kGradient, J::kPrecomputed, true},
               {"plain floor shader", false, L::kNone, J::kPrecomputed, false, true, 16, false,
                true},
               {"peel unshaded", true, L::kNone, J::kPrecomputed, false},
               {"peel unshaded unsplit", true, L::kNone, J::kPrecomputed, false, false},
               {"peel unshaded unsplit RGBA32F map", true, L::kNone, J::kPrecomputed, false, false,
                16, true},
               {"peel unshaded unsplit RGBA8 map", true, L::kNone, J::kPrecomputed, false, false, 8,
                false},
               {"peel gradient only", true, L::kGradient, J::kPrecomputed, false},
               {"peel gradient only unsplit", true, L::kGradient, J::kPrecomputed, false, false},
               {"peel eq. 6", true, L::kTransformed, J::kPrecomputed, false},
               {"peel eq. 6 unsplit", true, L::kTransformed, J::kPrecomputed, false, false},
               {"peel eq. 6+7 one draw per part", true, L::kBlended, J::kPrecomputed, true},
               {"peel eq. 6+7 J_D differences", true, L::kBlended, J::kFiniteDifferences, false}}) {
        render::VolumePassOptions po = plain;
        po.lighting = pr.lighting;
        po.jacobian = pr.jacobian;
        po.draw_per_slice = pr.per_slice;
        po.support_skip = pr.support_skip;
        po.displacement_bits = pr.bits;
        po.float_map_textures = pr.float_maps;
        po.floor_shader = pr.floor_shader;
        add("profile", e.name, pr.variant, 1.0, pr.displaced ? 64 : 0, size,
            TimeVolume(programs, pr.displaced ? peeled : bare, po, size, timer), p.ms, nullptr,
            std::nan(""));
      }
      // What the two accuracy knobs cost: each setting's image (float
      // colour, the bench's view) against the finest setting, map 128^3
      // sampled every 0.25 voxel, itself timed as the family's truth.
      const ibr::VolumeObjectData finest_map = ibr::MakeVolumeObject(volume, tf, peel, 128);
      render::VolumePassOptions finest = displaced;
      finest.sampling_distance_voxels = 0.25;
      const Measured reference = TimeVolume(programs, finest_map, finest, size, timer, true);
      add("finest", e.name, "peel 128^3 at 0.25 voxel", 0.25, 128, size, reference, 0, nullptr,
          0.0);
      // Times one setting and returns it with its error against `truth`.
      auto measure = [&](const ibr::VolumeObjectData& scene, const render::VolumePassOptions& po,
                         const core::ImageF& truth) {
        const Measured m = TimeVolume(programs, scene, po, size, timer, true);
        return std::pair{m, core::SummarizeErrors(ColorErrors(m.color, truth)).p95};
      };
      // The sampling rows against the same 64^3 map sampled every 0.25
      // voxel: against the 128^3 map their error would measure the map size
      // as much as the sampling.
      const core::ImageF sampling_truth =
          TimeVolume(programs, peeled, finest, size, timer, true).color;
      for (double sampling :
           o.quick ? std::vector<double>{0.5, 2.0} : std::vector<double>{0.5, 1.0, 2.0, 4.0}) {
        render::VolumePassOptions s = displaced;
        s.sampling_distance_voxels = sampling;
        const auto [m, error] = measure(peeled, s, sampling_truth);
        add("sampling", e.name, "peel 64^3", sampling, 64, size, m, 0, nullptr, error);
      }
      for (int map_size : o.quick ? std::vector<int>{16, 64} : std::vector<int>{16, 32, 64, 128}) {
        const ibr::VolumeObjectData m = ibr::MakeVolumeObject(volume, tf, peel, map_size);
        const auto [measured, error] = measure(m, displaced, reference.color);
        add("map_size", e.name, "peel", 1.0, map_size, size, measured, 0, nullptr, error);
      }
      // Correa 2006 Table 2 analogue: map size x stored bits -> the (D,
      // alpha) texture's bytes as uploaded (8/16-bit maps stay UNORM on the
      // GPU; the J_D textures are RGBA32F at any bits), time, and the
      // picture's colour error against the same map stored in 32 bits.
      for (int map_size : o.quick ? std::vector<int>{16, 64} : std::vector<int>{16, 32, 64, 128}) {
        const ibr::VolumeObjectData m = ibr::MakeVolumeObject(volume, tf, peel, map_size);
        render::VolumePassOptions by_bits = displaced;
        by_bits.displacement_bits = 32;
        const Measured full = TimeVolume(programs, m, by_bits, size, timer, true);
        const core::ErrorStats exact{};
        add("bits", e.name, "peel 32-bit RGBA32F map", 1.0, map_size, size, full, 0, nullptr,
            std::nan(""), &exact);
        for (const int bits : {16, 8}) {
          by_bits.displacement_bits = bits;
          const Measured q = TimeVolume(programs, m, by_bits, size, timer, true);
          const core::ErrorStats vs = core::SummarizeErrors(ColorErrors(q.color, full.color));
          add("bits", e.name, fmt::format("peel {}-bit RGBA{} map", bits, bits), 1.0, map_size,
              size, q, 0, nullptr, std::nan(""), &vs);
        }
      }
    }
    if (e.name == "neghip") {
      // Time against the rasterised proxy area: image sizes.
      for (int px : o.quick ? std::vector<int>{64, 128} : std::vector<int>{128, 256, 384, 512}) {
        add("area", e.name, "plain DVR (shaded)", 1.0, 0, px,
            TimeVolume(programs, bare, plain, px, timer), 0, nullptr, std::nan(""));
      }
    }
  }
  // R^2 of ms against area over the area sweep.
  std::vector<double> area_mpx, ms;
  for (const auto& row : table.rows()) {
    if (row[0] == "area") {
      area_mpx.push_back(std::stod(row[table.Column("area_Mpx")]));
      ms.push_back(std::stod(row[table.Column("ms_per_frame")]));
    }
  }
  if (area_mpx.size() >= 2) {
    const LineFit fit = FitLine(area_mpx, ms);
    // Degenerate data print NaN (FitLine reports 0, or r2 = 1 for constant times).
    auto spread = [](const std::vector<double>& v) {
      const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
      return *hi > *lo;
    };
    const bool x_spread = spread(area_mpx), y_spread = spread(ms);
    fmt::print(
        "time vs rasterised proxy area (neghip, {} sizes): {:.3f} ms per M px, R^2 = {:.3f}\n",
        area_mpx.size(), x_spread ? fit.slope : std::nan(""),
        x_spread && y_spread ? fit.r2 : std::nan(""));
  }
  fmt::print("{}", table.Format());
  fmt::print("ratios at {} px, sampling distance 1 voxel (same run):\n", size);
  for (const std::string& line : summary) fmt::print("  {}\n", line);
  table.WriteCsv(o.csv);
  const Table goals = VolumeGoalsTable(table);
  fmt::print("{}", goals.Format());
  goals.WriteCsv(VolumeGoalsPath(o.csv));
  if (!o.out.empty()) {
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
            o.out / "volume_time_vs_area.png");
    // The tooth's sweeps (Table 1-2 analogues), each on its own axis.
    PlotPng(subset("sampling"),
            {.title = "volume: peeled tooth, time vs sampling distance",
             .x_column = "sampling_voxels",
             .y_column = "ms_per_frame",
             .series_column = "variant",
             .x_label = "sampling distance (voxels)",
             .y_label = "ms/frame",
             .log_x = true},
            o.out / "volume_time_vs_sampling.png");
    PlotPng(subset("map_size"),
            {.title = "volume: peeled tooth, time vs displacement map size",
             .x_column = "map_size",
             .y_column = "ms_per_frame",
             .series_column = "variant",
             .x_label = "map texels per axis",
             .y_label = "ms/frame",
             .log_x = true},
            o.out / "volume_time_vs_map_size.png");
  }
  return table;
}

}  // namespace bench
