// The dataset directory: manifest round trips through streams, writer ->
// reader round trips of all images (depth bit-exact through EXR), staged
// output, and bad datasets giving InputError naming the file.
#include "capture/dataset.h"

#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <sstream>

#include "core/error.h"
#include "core/image_io.h"
#include "tests/support/gl_test.h"

namespace capture {
namespace {
namespace fs = std::filesystem;

Dataset SampleManifest() {
  Dataset d;
  d.cameras.emplace(1, Camera::Pinhole(8, 6, 10.125, 10.25, 4.0, 3.0));
  d.cameras.emplace(2, Camera::Orthographic(8, 6, 3.0 / 7.0, 3.0 / 7.0, 4, 3));
  d.views.push_back({"a", 1, LookAt({0.1, -3, 0.3}, {0, 0, 0}, {0, 0, 1}), "color/a.png",
                     "depth/a.exr", "mask/a.png", ""});
  d.views.push_back({"b", 2, LookAt({3, 0.2, 0}, {0, 0, 0}, {0, 0, 1}), "color/b.png", "", "", ""});
  d.bounds = Bounds{{-1, -1, -1}, {1, 1, 1.0 / 3.0}};
  d.depth_units = "m";
  return d;
}

TEST(Manifest, BoundsFlagParsesSixNumbers) {
  const Bounds b = ParseBounds("-1,-2,-3,1,2.5,3", "--bounds");
  EXPECT_EQ(b, (Bounds{{-1, -2, -3}, {1, 2.5, 3}}));
  for (const char* bad : {"", "1,2,3,4,5", "1,2,3,4,5,6,7", "1,2,3,4,5,x", "1,1,1,0,0,0"}) {
    EXPECT_THROW(ParseBounds(bad, "--bounds"), core::InputError) << bad;
  }
}

TEST(Manifest, StreamRoundTripIsExact) {
  const Dataset d = SampleManifest();
  std::stringstream s;
  WriteManifest(s, d);
  const Dataset back = ReadManifest(s, "mem");
  EXPECT_EQ(back, d);  // doubles compared bit for bit
}

void MakeViewImages(int w, int h, core::Image8& color, core::ImageF& depth, core::Image8& mask,
                    core::ImageF& normal) {
  color = core::Image8(w, h, 4);
  depth = core::ImageF(w, h, 1);
  mask = core::Image8(w, h, 1);
  normal = core::ImageF(w, h, 3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) color.at(x, y, c) = static_cast<uint8_t>(x * 30 + y * 7 + c);
      color.at(x, y, 3) = 255;
      depth.at(x, y) = (x + y) % 3 == 0 ? 0.0f : 1.0f / static_cast<float>(1 + x + 7 * y);
      mask.at(x, y) = depth.at(x, y) > 0 ? 255 : 0;
      normal.at(x, y, 2) = depth.at(x, y) > 0 ? 1.0f : 0.0f;
    }
  }
}

TEST(DatasetFiles, WriterReaderRoundTrip) {
  const fs::path dir = test_support::TestOutputDir() / "ds";
  core::Image8 color, mask;
  core::ImageF depth, normal;
  MakeViewImages(8, 6, color, depth, mask, normal);
  {
    DatasetWriter writer(dir);
    const int cam = writer.AddCamera(Camera::Pinhole(8, 6, 10, 10, 4, 3));
    writer.AddView("v0", cam, LookAt({0, 0, -2}, {0, 0, 0}, {0, -1, 0}), color, depth, mask,
                   normal);
    writer.AddView("v1", cam, LookAt({2, 0, 0}, {0, 0, 0}, {0, -1, 0}), color, {}, mask, {});
    writer.SetBounds({{-1, -1, -1}, {1, 1, 1}});
    writer.Commit();
  }
  const Dataset d = ReadDataset(dir, /*check_pixels=*/true);
  ASSERT_EQ(d.views.size(), 2u);
  EXPECT_EQ(d.LoadDepth(0), depth);  // EXR float32: exact
  EXPECT_EQ(d.LoadMask(0), mask);
  EXPECT_EQ(d.LoadNormal(0), normal);
  const core::Image8 rgb = d.LoadColor(1);
  EXPECT_EQ(rgb.channels(), 3);
  EXPECT_EQ(rgb.at(5, 4, 2), color.at(5, 4, 2));
  EXPECT_TRUE(d.views[1].depth.empty());
  EXPECT_THROW(d.LoadDepth(1), core::InputError);
}

TEST(DatasetFiles, FailedWriteLeavesNothing) {
  const fs::path dir = test_support::TestOutputDir() / "never";
  core::Image8 color, mask;
  core::ImageF depth, normal;
  MakeViewImages(8, 6, color, depth, mask, normal);
  {
    DatasetWriter writer(dir);
    const int cam = writer.AddCamera(Camera::Pinhole(8, 6, 10, 10, 4, 3));
    writer.AddView("v0", cam, {}, color, depth, mask, normal);
    core::ImageF wrong(7, 6, 1);
    EXPECT_THROW(writer.AddView("v1", cam, {}, color, wrong, mask, normal), core::InputError);
  }
  EXPECT_FALSE(fs::exists(dir));
  for (const auto& e : fs::directory_iterator(dir.parent_path()))
    ADD_FAILURE() << "left behind: " << e.path();
}

// ---- bad datasets ----

struct BadDataset {
  const char* what;
  std::function<void(const fs::path& dir)> spoil;  // applied to a valid dataset
  std::string expect_in_message;                   // a file name or key
  bool check_pixels = false;
};

void RewriteManifest(const fs::path& dir, const std::function<void(std::string&)>& edit) {
  std::ifstream in(dir / "dataset.json");
  std::string s((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  edit(s);
  std::ofstream(dir / "dataset.json") << s;
}

void Replace(std::string& s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  ASSERT_NE(at, std::string::npos) << from;
  s.replace(at, from.size(), to);
}

TEST(DatasetBadInput, EveryCaseThrowsInputErrorNamingTheFile) {
  const std::vector<BadDataset> cases = {
      {"missing manifest", [](const fs::path& d) { fs::remove(d / "dataset.json"); },
       "dataset.json"},
      {"truncated manifest",
       [](const fs::path& d) {
         RewriteManifest(d, [](std::string& s) { s.resize(s.size() / 2); });
       },
       "dataset.json"},
      {"not json",
       [](const fs::path& d) { std::ofstream(d / "dataset.json") << "\x01\x02garbage"; },
       "dataset.json"},
      {"wrong format tag",
       [](const fs::path& d) {
         RewriteManifest(d, [](std::string& s) { Replace(s, "ibr-dataset", "other"); });
       },
       "dataset.json"},
      {"unknown model",
       [](const fs::path& d) {
         RewriteManifest(d, [](std::string& s) { Replace(s, "\"PINHOLE\"", "\"PINHOL\""); });
       },
       "dataset.json"},
      {"distorted camera",
       [](const fs::path& d) {
         RewriteManifest(d, [](std::string& s) { Replace(s, "\"PINHOLE\"", "\"SIMPLE_RADIAL\""); });
       },
       "dataset.json"},
      {"unknown camera id",
       [](const fs::path& d) {
         RewriteManifest(d, [](std::string& s) { Replace(s, "\"camera\": 1", "\"camera\": 9"); });
       },
       "dataset.json"},
      {"NaN-ish param (string)",
       [](const fs::path& d) {
         RewriteManifest(
             d, [](std::string& s) { Replace(s, "\"params\": [", "\"params\": [\"nan\", "); });
       },
       "dataset.json"},
      {"non-orthonormal pose",
       [](const fs::path& d) {
         RewriteManifest(d, [](std::string& s) {
           Replace(s, "\"cam_from_world\": [\n        [", "\"cam_from_world\": [\n        [3.0, ");
         });
       },
       "dataset.json"},
      {"path escapes",
       [](const fs::path& d) {
         RewriteManifest(d,
                         [](std::string& s) { Replace(s, "\"color/v0.png\"", "\"../v0.png\""); });
       },
       "dataset.json"},
      {"missing colour file", [](const fs::path& d) { fs::remove(d / "color/v0.png"); },
       "color/v0.png"},
      {"wrong-size depth",
       [](const fs::path& d) { core::WriteImage(d / "depth/v0.exr", core::ImageF(5, 5, 1)); },
       "depth/v0.exr"},
      {"corrupt colour png",
       [](const fs::path& d) { std::ofstream(d / "color/v0.png") << "\x89PNG\r\n\x1a\nbroken"; },
       "color/v0.png"},
      {"negative depth",
       [](const fs::path& d) {
         core::WriteImage(d / "depth/v0.exr", core::ImageF(8, 6, 1, -1.0f));
       },
       "depth/v0.exr", true},
      {"NaN normal",
       [](const fs::path& d) { core::WriteImage(d / "normal/v0.exr", core::ImageF(8, 6, 3, NAN)); },
       "normal/v0.exr", true},
      {"depth with 3 channels",
       [](const fs::path& d) { core::WriteImage(d / "depth/v0.exr", core::ImageF(8, 6, 3)); },
       "depth/v0.exr", true},
  };
  for (const auto& c : cases) {
    const fs::path dir = test_support::TestOutputDir() / "bad";
    core::Image8 color, mask;
    core::ImageF depth, normal;
    MakeViewImages(8, 6, color, depth, mask, normal);
    {
      DatasetWriter writer(dir);
      const int cam = writer.AddCamera(Camera::Pinhole(8, 6, 10, 10, 4, 3));
      writer.AddView("v0", cam, {}, color, depth, mask, normal);
      writer.Commit();
    }
    c.spoil(dir);
    try {
      ReadDataset(dir, c.check_pixels);
      ADD_FAILURE() << c.what << ": no error";
    } catch (const core::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(c.expect_in_message), std::string::npos)
          << c.what << ": " << e.what();
    }
    fs::remove_all(dir);
  }
}

}  // namespace
}  // namespace capture
