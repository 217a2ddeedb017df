// Smoke test of `ibr bench volume`'s driver (bench/volume_bench.h) on its
// --quick run without the peer: the CSV has the documented columns, one row
// per measured configuration with as many fields as columns, finite positive
// times and areas, the accuracy knobs' errors against the finest setting,
// and the plots exist. Times are printed, not asserted.
#include "bench/volume_bench.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "bench/report_summary.h"
#include "tests/support/gl_test.h"

namespace bench {
namespace {

std::vector<std::string> Split(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream in(line);
  std::string f;
  while (std::getline(in, f, ',')) fields.push_back(f);
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  return fields;
}

double Number(const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  return end != text.c_str() && *end == '\0' ? v : std::nan("");
}

class VolumeBenchTest : public test_support::GlTest {};

// The VTK peer runs when its tools are installed (xvfb-run and Debian's
// python3-vtk9, as the bench calls them); without them its rows are absent
// and the test says so.
bool VtkPeerAvailable() {
  return std::system(
             "command -v xvfb-run >/dev/null 2>&1 && /usr/bin/python3 -c 'import vtk' "
             ">/dev/null 2>&1") == 0;
}

TEST_F(VolumeBenchTest, QuickRunWritesEveryConfigurationAndThePlots) {
  const auto data = test_support::SharedData("volumes");
  if (data.empty()) GTEST_SKIP() << "../shared/data is absent";
  VolumeBenchOptions options;
  const std::filesystem::path dir = test_support::TestOutputDir();
  options.csv = dir / "volume.csv";
  options.out = dir;
  options.shared_data = data.parent_path();
  options.quick = true;
  options.peer = VtkPeerAvailable();
  if (!options.peer) std::printf("xvfb-run or python3-vtk9 missing: no VTK peer rows checked\n");
  RunVolumeBench(options);
  std::ifstream in(options.csv);
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  const std::vector<std::string> columns = Split(line);
  ASSERT_EQ(columns, VolumeBenchColumns());
  std::map<std::string, int> at;
  for (size_t c = 0; c < columns.size(); ++c) at[columns[c]] = static_cast<int>(c);
  std::set<std::string> sweeps, volumes, displaced_floors, prewarped;
  std::map<double, double> sampling_error;           // sampling distance -> p95 colour error
  std::map<std::pair<int, int>, double> bits_bytes;  // (map size, bits) -> bytes per map
  int rows = 0, brick_rows = 0;
  while (std::getline(in, line)) {
    const std::vector<std::string> f = Split(line);
    ASSERT_EQ(f.size(), columns.size()) << line;  // a comma in a name would shift the fields
    const auto num = [&](const char* column) { return Number(f[at.at(column)]); };
    ++rows;
    sweeps.insert(f[0]);
    volumes.insert(f[1]);
    const std::string& variant = f[at["variant"]];
    if (f[0] == "bricks") {
      ++brick_rows;
      EXPECT_GT(num("ratio_to_plain"), 0) << line;
    }
    if (f[0] == "peer") {
      // The peer's warped volume: its frame, resample time and its check
      // against core::Displace (finite, within a few 1/255: the same map).
      EXPECT_EQ(variant, "vtk prewarped") << line;
      prewarped.insert(f[1]);
      for (const char* c : {"ms_per_frame", "vtk_ms", "vtk_min_ms", "vtk_resample_ms"})
        EXPECT_GT(num(c), 0) << c << " in: " << line;
      EXPECT_TRUE(num("vtk_warp_p95_error") >= 0 && num("vtk_warp_p95_error") < 4) << line;
      continue;
    }
    for (const char* c : {"ms_per_frame", "area_Mpx", "fill_fraction", "ns_per_fragment"})
      EXPECT_GT(num(c), 0) << c << " in: " << line;
    EXPECT_GE(num("slices"), 1) << line;
    if (variant == "displaced floor") {
      displaced_floors.insert(f[1]);
      EXPECT_DOUBLE_EQ(num("map_coverage"), 1.0) << line;  // every fragment displaced
    }
    // A map's row: its bits, its texture's bytes (4 channels of bits / 8,
    // or 4 bytes when dequantised to float) and the displaced share.
    if (!f[at["map_bits"]].empty()) {
      const double texels = std::pow(num("map_size"), 3);
      EXPECT_GT(num("bytes_per_map"), 0) << line;
      EXPECT_LE(num("bytes_per_map"), texels * 16) << line;
      EXPECT_TRUE(num("map_coverage") >= 0 && num("map_coverage") <= 1) << line;
    }
    // Table 2's analogue: bytes as uploaded, the error against the 32-bit
    // map (0 for itself, finite for 8 and 16 bits).
    if (f[0] == "bits") {
      const int bits = static_cast<int>(num("map_bits"));
      bits_bytes[{static_cast<int>(num("map_size")), bits}] = num("bytes_per_map");
      const double p95 = num("p95_color_error_vs_32bit"), max = num("max_color_error_vs_32bit");
      if (bits == 32) {
        EXPECT_EQ(p95, 0.0) << line;
      } else {
        EXPECT_TRUE(p95 >= 0 && p95 <= max && max <= 255) << line;
      }
    }
    // The accuracy knobs' rows carry their error against the finest
    // setting (the finest itself: 0); the others none.
    const double error = num("p95_color_error_vs_finest");
    if (f[0] == "finest") {
      EXPECT_EQ(error, 0.0) << line;
    } else if (f[0] == "sampling" || f[0] == "map_size") {
      EXPECT_TRUE(error >= 0 && error < 255) << line;
      if (f[0] == "sampling") sampling_error[num("sampling_voxels")] = error;
    } else {
      EXPECT_TRUE(f[at["p95_color_error_vs_finest"]].empty()) << line;
    }
  }
  std::set<std::string> expected_sweeps = {"floor",  "volume",   "unsplit",  "bricks", "profile",
                                           "finest", "sampling", "map_size", "area",   "bits"};
  if (options.peer) expected_sweeps.insert("peer");
  EXPECT_EQ(sweeps, expected_sweeps);
  const std::set<std::string> benched = {"tooth", "neghip", "bucky"};
  EXPECT_EQ(displaced_floors, benched);
  if (options.peer) {
    EXPECT_EQ(prewarped, benched);
  }
  // Each map size at 8, 16 and 32 bits: 4, 8 and 16 bytes a texel (RGBA8
  // and RGBA16 kept on the GPU, RGBA32F).
  ASSERT_EQ(bits_bytes.size(), 2u * 3u);
  for (const int map_size : {16, 64}) {
    const double b32 = bits_bytes.at({map_size, 32});
    EXPECT_GT(b32, 0) << map_size;
    EXPECT_EQ(bits_bytes.at({map_size, 16}) * 2, b32) << map_size;
    EXPECT_EQ(bits_bytes.at({map_size, 8}) * 4, b32) << map_size;
  }
  // Three brick sizes besides the default's "volume" row, per volume.
  EXPECT_EQ(brick_rows, 3 * 3);
  // Sampling 4x farther apart than the finest's step costs accuracy; half a
  // voxel apart is nearer the finest (0.25 voxel) than two voxels.
  ASSERT_EQ(sampling_error.size(), 2u);
  EXPECT_GT(sampling_error.at(2.0), 0.0);
  EXPECT_LT(sampling_error.at(0.5), sampling_error.at(2.0));
  EXPECT_EQ(volumes, (std::set<std::string>{"calibration", "tooth", "neghip", "bucky"}));
  EXPECT_GE(rows, 18);
  for (const char* png :
       {"volume_time_vs_area.png", "volume_time_vs_sampling.png", "volume_time_vs_map_size.png"})
    EXPECT_TRUE(std::filesystem::exists(dir / png)) << png;

  // The goals beside the CSV: each goal's row, measured for every volume
  // with finite figures, and met stated (yes/no for a goal, "-" for a
  // stated figure); the peer's goals n/a without the peer.
  const Table goals = ReadCsv(VolumeGoalsPath(options.csv));
  EXPECT_EQ(goals.columns(),
            (std::vector<std::string>{"quantity", "goal", "measured", "met", "note"}));
  for (const std::vector<std::string>& f : goals.rows()) {
    const bool peer_goal = f[0].find("VTK") != std::string::npos;
    if (peer_goal && !options.peer) {
      EXPECT_EQ(f[3], "n/a") << f[0];
      continue;
    }
    for (const std::string& name : benched) {
      // "tooth 1.31x": the volume's name, then a finite number.
      const size_t p = f[2].find(name + " ");
      ASSERT_NE(p, std::string::npos) << name << " in: " << f[2];
      EXPECT_TRUE(std::isfinite(std::strtod(f[2].c_str() + p + name.size() + 1, nullptr))) << f[2];
    }
    if (f[1] == "stated") {
      EXPECT_EQ(f[3], "-") << f[0];
    } else {
      EXPECT_TRUE(f[3] == "yes" || f[3] == "no") << f[0];
    }
  }
  EXPECT_EQ(goals.rows().size(), 5u);
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace bench
