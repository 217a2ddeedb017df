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

TEST_F(VolumeBenchTest, QuickRunWritesEveryConfigurationAndThePlots) {
  const auto data = test_support::SharedData("volumes");
  if (data.empty()) GTEST_SKIP() << "../shared/data is absent";
  VolumeBenchOptions options;
  const std::filesystem::path dir = test_support::TestOutputDir();
  options.csv = dir / "volume.csv";
  options.out = dir;
  options.shared_data = data.parent_path();
  options.quick = true;
  options.peer = false;
  RunVolumeBench(options);
  std::ifstream in(options.csv);
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  const std::vector<std::string> columns = Split(line);
  const std::vector<std::string> expected = {"sweep",          "volume",
                                             "variant",        "sampling_voxels",
                                             "map_size",       "size_px",
                                             "slices",         "ms_per_frame",
                                             "area_Mpx",       "fill_fraction",
                                             "ratio_to_plain", "vtk_ms",
                                             "vtk_min_ms",     "p95_color_error_vs_finest"};
  ASSERT_EQ(columns, expected);
  std::set<std::string> sweeps, volumes;
  std::map<double, double> sampling_error;  // sampling distance -> p95 colour error
  int rows = 0, brick_rows = 0;
  while (std::getline(in, line)) {
    const std::vector<std::string> f = Split(line);
    ASSERT_EQ(f.size(), columns.size()) << line;  // a comma in a name would shift the fields
    ++rows;
    sweeps.insert(f[0]);
    if (f[0] == "bricks") {
      ++brick_rows;
      EXPECT_GT(Number(f[10]), 0) << line;  // ratio to plain DVR
    }
    volumes.insert(f[1]);
    for (int c : {7, 8, 9}) EXPECT_GT(Number(f[c]), 0) << columns[c] << " in: " << line;
    EXPECT_GE(Number(f[6]), 1) << line;  // slices
    // The accuracy knobs' rows carry their error against the finest
    // setting (the finest itself: 0); the others none.
    const double error = Number(f[13]);
    if (f[0] == "finest") {
      EXPECT_EQ(error, 0.0) << line;
    } else if (f[0] == "sampling" || f[0] == "map_size") {
      EXPECT_TRUE(error >= 0 && error < 255) << line;
      if (f[0] == "sampling") sampling_error[Number(f[3])] = error;
    } else {
      EXPECT_TRUE(f[13].empty()) << line;
    }
  }
  EXPECT_EQ(sweeps, (std::set<std::string>{"floor", "volume", "unsplit", "bricks", "profile",
                                           "finest", "sampling", "map_size", "area"}));
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
  EXPECT_NO_GL_ERROR();
}

}  // namespace
}  // namespace bench
