// The map limit (ibr::kMaxMaps, 4096: an input limit, the same number as the
// dataset reader's view limit) is checked on the manifest, before a view is
// parsed or any image is opened: every manifest here names images that do
// not exist, so an error about anything but the count means an image was
// looked for first.
#include "ibr/dataset_maps.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "core/error.h"
#include "tests/support/gl_test.h"
#include "tests/support/input_error.h"

namespace ibr {
namespace {
namespace fs = std::filesystem;

// DIR/dataset.json with `views` orthographic views, each naming colour, depth
// and mask files that do not exist.
fs::path ManifestWithViews(const std::string& name, int views) {
  const fs::path dir = test_support::TestOutputDir() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream out(dir / "dataset.json");
  out << R"({"format": "ibr-dataset", "version": 1,
  "bounds": {"min": [-1, -1, -1], "max": [1, 1, 1]},
  "cameras": [{"id": 1, "model": "ORTHOGRAPHIC", "width": 32, "height": 32,
               "params": [16, 16, 16, 16]}],
  "views": [)";
  for (int i = 0; i < views; ++i) {
    out << (i ? ",\n" : "\n") << R"({"name": "v)" << i
        << R"(", "camera": 1, "cam_from_world": [[1,0,0,0],[0,1,0,0],[0,0,1,3]], "color": "color/v)"
        << i << R"(.png", "depth": "depth/v)" << i << R"(.exr", "mask": "mask/v)" << i
        << R"(.png"})";
  }
  out << "]}\n";
  return dir;
}

using test_support::InputErrorOf;

TEST(MapDataset, HundredThousandViewsAreRefusedOnTheManifest) {
  const fs::path dir = ManifestWithViews("views_100000", 100000);
  const std::string manifest = (dir / "dataset.json").string();
  EXPECT_EQ(InputErrorOf([&] { ReadMapDataset(dir); }),
            "ReadManifest: '" + manifest + "': more than 4096 views; at most 4096 are supported");
  // Any dataset: the dataset limit (the same number), also before a view is parsed.
  EXPECT_EQ(InputErrorOf([&] { capture::ReadDataset(dir); }),
            "ReadManifest: '" + manifest + "': more than 4096 views; at most 4096 are supported");
  EXPECT_FALSE(fs::exists(dir / "color"));
}

TEST(MapDataset, OneMapOverTheLimitIsRefusedBeforeAnyImage) {
  ASSERT_EQ(kMaxMaps, 4096);
  const fs::path dir = ManifestWithViews("views_4097", kMaxMaps + 1);
  EXPECT_NE(InputErrorOf([&] {
              ReadMapDataset(dir);
            }).find("more than 4096 views; at most 4096 are supported"),
            std::string::npos);
  // The limit itself passes the count, and the reader then looks for the
  // images (which is how the two tests above know none was opened).
  const fs::path ok = ManifestWithViews("views_4096", kMaxMaps);
  const std::string error = InputErrorOf([&] { ReadMapDataset(ok); });
  EXPECT_NE(error.find("file does not exist"), std::string::npos) << error;
  EXPECT_NE(error.find("color/v0.png"), std::string::npos) << error;
  // A dataset of 4096 views is fine as cameras too: it gets as far as the images.
  EXPECT_NE(InputErrorOf([&] { capture::ReadDataset(ok); }).find("file does not exist"),
            std::string::npos);
}

// Every element of the top-level "views" counts, whatever its type (the
// reader then refuses it as a view), and a "views" key anywhere but the top
// level counts nothing.
TEST(MapDataset, TheCountIsOfTopLevelViewElementsOfAnyType) {
  const auto manifest = [](const std::string& name, const std::string& views,
                           const std::string& extra) {
    const fs::path dir = test_support::TestOutputDir() / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    std::ofstream(dir / "dataset.json") << R"({"format": "ibr-dataset", "version": 1, )" << extra
                                        << R"("cameras": [], "views": )" << views << "}\n";
    return dir;
  };
  std::string mixed = "[";
  const char* const kinds[] = {"1", "[2, 3]", "{}"};  // a scalar, an array, an object
  for (int i = 0; i <= kMaxMaps; ++i) {
    if (i > 0) mixed += ',';
    mixed += kinds[i % 3];
  }
  mixed += "]";
  EXPECT_NE(InputErrorOf([&] {
              ReadMapDataset(manifest("views_mixed_4097", mixed, ""));
            }).find("more than 4096 views"),
            std::string::npos);
  // 4097 inner "views" arrays of one element each under another key: not views.
  std::string nested = R"("other": {"views": [)";
  for (int i = 0; i <= kMaxMaps; ++i) nested += i > 0 ? ",[0]" : "[0]";
  nested += "]}, ";
  const std::string error =
      InputErrorOf([&] { ReadMapDataset(manifest("views_nested", "[]", nested)); });
  EXPECT_EQ(error.find("more than"), std::string::npos) << error;
  EXPECT_FALSE(error.empty());  // no views at all is refused for what it is
}

}  // namespace
}  // namespace ibr
