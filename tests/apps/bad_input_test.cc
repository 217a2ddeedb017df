// A corpus of bad command lines and hostile inputs, across every subcommand,
// run against the real `ibr` binary. Each case asserts: the exit code (1 for
// our input errors, CLI11's 100..120 for malformed command lines), exactly one
// line on stderr, "ibr: error: ..." naming the cause, every input file
// byte-for-byte unchanged, and nothing at --out (no output, no staging
// folder). Commands run with --log-level error so that stderr holds only
// errors and any library chatter (which fails the one-line check).
//
// Also here: SIGINT / SIGTERM / SIGKILL sent to a running `ibr capture`, and
// a user's folder given as --out.
#include <fcntl.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include "core/image.h"
#include "core/image_io.h"
#include "tests/support/gl_test.h"
#include "tests/support/png_claimed_size.h"
#include "tests/support/run_command.h"

extern char** environ;

namespace {
namespace fs = std::filesystem;
using nlohmann::json;
using test_support::CountLines;
using test_support::IbrBinary;
using test_support::PngWithClaimedSize;
using test_support::Quote;
using test_support::RunCommand;
using test_support::Slurp;
using test_support::Spit;

// Every file (and folder, and link) under `dir` with a hash of its bytes.
std::map<std::string, uint64_t> Snapshot(const fs::path& dir) {
  std::map<std::string, uint64_t> files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    uint64_t h = 1469598103934665603ull;  // FNV-1a
    if (e.is_regular_file() && !e.is_symlink()) {
      for (unsigned char c : Slurp(e.path())) h = (h ^ c) * 1099511628211ull;
    }
    files[fs::relative(e.path(), dir).generic_string()] = h;
  }
  return files;
}

// ---- Fixtures, made once -----------------------------------------------------

struct Fixtures {
  fs::path root;
  fs::path dataset;  // a valid 6-view cube capture of the sphere, 32 px
  fs::path persp;    // a valid ring:4 capture (perspective), 32 px
};

// Made on first use (inside the first test that needs them).
const Fixtures& GetFixtures() {
  static const Fixtures fixtures = [] {
    Fixtures f;
    const char* root = std::getenv("IBR_TEST_OUTPUT");
    f.root = fs::path(root ? root : "test-output") / "bad_input_fixtures";
    fs::remove_all(f.root);
    fs::create_directories(f.root);
    f.dataset = f.root / "cube";
    f.persp = f.root / "ring";
    for (const auto& [dir, rig] : {std::pair{f.dataset, "cube"}, std::pair{f.persp, "ring:4"}}) {
      const auto r = RunCommand(IbrBinary() + " --log-level error capture --shape sphere --rig " +
                                rig + " --size 32 --out " + Quote(dir));
      if (r.exit_code != 0) ADD_FAILURE() << "fixture capture failed: " << r.err;
    }
    return f;
  }();
  return fixtures;
}

// Copies the good dataset into `dir` and applies `edit` to its manifest.
void DatasetWith(const fs::path& dir, const std::function<void(json&)>& edit,
                 const fs::path& source = {}) {
  fs::create_directories(dir.parent_path());
  fs::copy(source.empty() ? GetFixtures().dataset : source, dir, fs::copy_options::recursive);
  fs::remove(dir / ".ibr-output");  // a user's copy, not an ibr output
  json j = json::parse(Slurp(dir / "dataset.json"));
  edit(j);
  Spit(dir / "dataset.json", j.dump(1));
}

// ---- The corpus --------------------------------------------------------------

constexpr int kCli = -100;  // "a CLI11 parse error": exit code 100..120

struct Case {
  std::string name;
  // Prepares inputs under `dir` (which is empty) and returns the arguments
  // after `ibr`; `out` is where the command is told to write (must stay absent
  // unless it already exists as an input, which must then stay unchanged).
  std::function<std::string(const fs::path& dir, const fs::path& out)> make;
  std::string expect;  // a substring of the error line
  int exit_code = 1;
};

std::vector<Case> Corpus() {
  std::vector<Case> cases;
  auto add = [&](std::string name,
                 std::function<std::string(const fs::path&, const fs::path&)> make,
                 std::string expect, int exit_code = 1) {
    cases.push_back({std::move(name), std::move(make), std::move(expect), exit_code});
  };
  // OUT, CUBE and RING in `args` become --out's path and the fixtures'.
  auto fixed = [](std::string args) {
    return [args](const fs::path&, const fs::path& out) {
      std::string a = args;
      for (const auto& [token, path] :
           {std::pair{"OUT", out}, std::pair{"CUBE", GetFixtures().dataset},
            std::pair{"RING", GetFixtures().persp}}) {
        const size_t at = a.find(token);
        if (at != std::string::npos) a.replace(at, std::string(token).size(), Quote(path));
      }
      return a;
    };
  };
  const std::string cube = "CUBE";

  // -- the command line itself
  add("unknown_subcommand", fixed("frobnicate"), "unknown subcommand 'frobnicate' (valid: ");
  add("unknown_import_kind", fixed("import frob x --out OUT"), "unknown subcommand 'frob'");
  add("unknown_export_kind", fixed("export frob x --out OUT"), "unknown subcommand 'frob'");
  add("unknown_bench", fixed("bench frob"), "unknown subcommand 'frob'");
  add("no_subcommand", fixed(""), "subcommand", kCli);
  add("bad_log_level", fixed("--log-level loud info"), "--log-level", kCli);
  add("unknown_flag", fixed("capture --shape sphere --bogus --out OUT"), "--bogus", kCli);
  add("render_no_dataset", fixed("render --orbit 1 --out OUT"), "DATASET", kCli);
  add("bench_deform_two_onlys",
      fixed("bench deform --sdf-only --workloads-only --csv OUT/d.csv --out OUT"),
      "--sdf-only excludes --workloads-only", kCli);

  // -- outputs: never over a user's folder, never over or inside an input
  auto user_docs = [](const fs::path& dir) {
    const fs::path docs = dir / "Documents";
    Spit(docs / "letter.txt", "dear");
    Spit(docs / "taxes" / "2025.pdf", "%PDF-1.4");
    return docs;
  };
  add(
      "capture_out_user_folder",
      [=](const fs::path& dir, const fs::path&) {
        return "capture --shape sphere --rig cube --size 16 --out " + Quote(user_docs(dir));
      },
      "is not an earlier ibr output");
  add(
      "capture_out_is_a_file",
      [](const fs::path& dir, const fs::path&) {
        Spit(dir / "notes.txt", "x");
        return "capture --shape sphere --rig cube --size 16 --out " + Quote(dir / "notes.txt");
      },
      "exists and is not a folder");
  add(
      "capture_out_symlink_to_user_folder",
      [=](const fs::path& dir, const fs::path&) {
        fs::create_directory_symlink(user_docs(dir), dir / "link");
        return "capture --shape sphere --rig cube --size 16 --out " + Quote(dir / "link");
      },
      "symbolic link");
  add(
      "capture_out_earlier_output_with_user_file",
      [](const fs::path& dir, const fs::path&) {
        DatasetWith(dir / "D", [](json&) {});
        fs::copy_file(GetFixtures().dataset / ".ibr-output", dir / "D" / ".ibr-output");
        Spit(dir / "D" / "my_notes.txt", "mine");
        return "capture --shape sphere --rig cube --size 16 --out " + Quote(dir / "D");
      },
      "holds 'my_notes.txt', which ibr did not write");
  add(
      "render_out_is_input",
      [](const fs::path& dir, const fs::path&) {
        DatasetWith(dir / "D", [](json&) {});
        return "render " + Quote(dir / "D") + " --orbit 1 --size 16 --out " + Quote(dir / "D");
      },
      "is also an input");
  add(
      "render_out_is_input_via_dotdot",
      [](const fs::path& dir, const fs::path&) {
        DatasetWith(dir / "D", [](json&) {});
        fs::create_directories(dir / "x");
        return "render " + Quote(dir / "D") + " --orbit 1 --size 16 --out " +
               Quote(dir / "x" / ".." / "D");
      },
      "is also an input");
  add(
      "render_out_inside_input",
      [](const fs::path& dir, const fs::path&) {
        DatasetWith(dir / "D", [](json&) {});
        return "render " + Quote(dir / "D") + " --orbit 1 --size 16 --out " +
               Quote(dir / "D" / "renders");
      },
      "is inside the input");
  add(
      "render_out_holds_input",
      [](const fs::path& dir, const fs::path&) {
        DatasetWith(dir / "in" / "D", [](json&) {});
        return "render " + Quote(dir / "in" / "D") + " --orbit 1 --size 16 --out " +
               Quote(dir / "in");
      },
      "holds the input");
  add(
      "render_out_is_cameras_dataset",
      [](const fs::path& dir, const fs::path&) {
        DatasetWith(dir / "D", [](json&) {});
        DatasetWith(dir / "C", [](json&) {});
        return "render " + Quote(dir / "D") + " --cameras " + Quote(dir / "C") + " --out " +
               Quote(dir / "C");
      },
      "is also an input");
  add(
      "render_out_user_folder",
      [=](const fs::path& dir, const fs::path&) {
        return "render " + Quote(GetFixtures().dataset) + " --orbit 1 --size 16 --out " +
               Quote(user_docs(dir));
      },
      "is not an earlier ibr output");
  add(
      "export_out_is_input",
      [](const fs::path& dir, const fs::path&) {
        DatasetWith(
            dir / "D", [](json&) {}, GetFixtures().persp);
        return "export colmap " + Quote(dir / "D") + " --out " + Quote(dir / "D");
      },
      "is also an input");
  add(
      "export_out_inside_input",
      [](const fs::path& dir, const fs::path&) {
        DatasetWith(
            dir / "D", [](json&) {}, GetFixtures().persp);
        return "export colmap " + Quote(dir / "D") + " --out " + Quote(dir / "D" / "ws");
      },
      "is inside the input");
  add(
      "export_out_user_folder",
      [=](const fs::path& dir, const fs::path&) {
        return "export colmap " + Quote(GetFixtures().persp) + " --out " + Quote(user_docs(dir));
      },
      "is not an earlier ibr output");
  add(
      "import_out_is_source",
      [](const fs::path& dir, const fs::path&) {
        Spit(dir / "src" / "x_par.txt", "1\n");
        return "import middlebury " + Quote(dir / "src") + " --out " + Quote(dir / "src");
      },
      "is also an input");
  add(
      "demo_out_user_folder",
      [=](const fs::path& dir, const fs::path&) {
        return "demo --size 64 --out " + Quote(user_docs(dir));
      },
      "is not an earlier ibr output");
  add("displace_out_missing_folder", fixed("displace --out /nonexistent-ibr-dir/x.png"),
      "does not exist");
  add("displace_out_not_png", fixed("displace --out OUT"), "must end in .png");

  // -- dataset manifests (each through info, render and export)
  struct Edit {
    std::string name;
    std::function<void(json&)> edit;
    std::string expect;
  };
  const std::vector<Edit> edits = {
      {"bounds_1e38",
       [](json& j) {
         j["bounds"] = {{"min", {-1e38, -1e38, -1e38}}, {"max", {1e38, 1e38, 1e38}}};
       },
       "coordinates beyond"},
      {"bounds_1e-16_wide",
       [](json& j) {
         j["bounds"] = {{"min", {0, 0, 0}}, {"max", {1e-16, 1, 1}}};
       },
       "side x is 1e-16"},
      {"bounds_thin_for_float",
       [](json& j) {
         j["bounds"] = {{"min", {1e5, 0, 0}}, {"max", {1e5 + 1e-3, 1, 1}}};
       },
       "side x"},
      {"bounds_min_gt_max",
       [](json& j) {
         j["bounds"] = {{"min", {1, 0, 0}}, {"max", {0, 1, 1}}};
       },
       "min > max"},
      {"bounds_two_numbers",
       [](json& j) {
         j["bounds"]["min"] = {0, 0};
       },
       "expected 3 numbers"},
      {"width_64_5", [](json& j) { j["cameras"][0]["width"] = 64.5; }, "64.5 is not an integer"},
      {"width_string", [](json& j) { j["cameras"][0]["width"] = "32"; }, "is not an integer"},
      {"width_zero", [](json& j) { j["cameras"][0]["width"] = 0; }, "camera size 0x32"},
      {"width_huge", [](json& j) { j["cameras"][0]["width"] = 100000; }, "camera size 100000x32"},
      {"width_1e300", [](json& j) { j["cameras"][0]["width"] = 1e300; }, "is not an integer"},
      {"height_negative", [](json& j) { j["cameras"][0]["height"] = -32; }, "camera size 32x-32"},
      {"scale_zero", [](json& j) { j["cameras"][0]["params"][0] = 0.0; }, "must be positive"},
      {"scale_1e-30", [](json& j) { j["cameras"][0]["params"][0] = 1e-30; }, "image span"},
      {"scale_1e30", [](json& j) { j["cameras"][0]["params"][1] = 1e30; }, "image span"},
      {"principal_point_far", [](json& j) { j["cameras"][0]["params"][2] = 1e9; },
       "principal point"},
      {"params_count",
       [](json& j) {
         j["cameras"][0]["params"] = {1.0, 2.0};
       },
       "needs 4 parameters"},
      {"model_unknown", [](json& j) { j["cameras"][0]["model"] = "FISHEYE9"; },
       "unknown camera model 'FISHEYE9'"},
      {"model_distorted",
       [](json& j) {
         j["cameras"][0]["model"] = "OPENCV";
         j["cameras"][0]["params"] = {30.0, 30.0, 16.0, 16.0, 0.01, 0.0, 0.0, 0.0};
       },
       "has lens distortion"},
      {"distortion_folds",
       [](json& j) {
         j["cameras"][0]["model"] = "SIMPLE_RADIAL";
         j["cameras"][0]["params"] = {30.0, 16.0, 16.0, -5.0};
       },
       "cannot be undistorted"},
      {"rotation_scaled", [](json& j) { j["views"][0]["cam_from_world"][0][0] = 2.0; },
       "not orthonormal"},
      {"rotation_reflection",
       [](json& j) {
         for (int c = 0; c < 3; ++c)
           j["views"][0]["cam_from_world"][0][c] =
               -j["views"][0]["cam_from_world"][0][c].get<double>();
       },
       "reflection"},
      {"translation_1e300", [](json& j) { j["views"][0]["cam_from_world"][0][3] = 1e300; },
       "camera centre"},
      {"pose_two_rows", [](json& j) { j["views"][0]["cam_from_world"].erase(2); },
       "expected 3 rows"},
      {"camera_id_missing", [](json& j) { j["views"][0]["camera"] = 99; }, "unknown camera id 99"},
      {"duplicate_view", [](json& j) { j["views"][1]["name"] = j["views"][0]["name"]; },
       "duplicate view name"},
      {"path_escapes", [](json& j) { j["views"][0]["color"] = "../../etc/passwd"; },
       "bad color path"},
      {"path_absolute", [](json& j) { j["views"][0]["depth"] = "/etc/passwd"; },
       "bad path '/etc/passwd'"},
      {"no_views", [](json& j) { j["views"] = json::array(); }, "no views"},
      {"5000_views",
       [](json& j) {
         json v = j["views"][0];
         j["views"] = json::array();
         for (int i = 0; i < 5000; ++i) {
           v["name"] = fmt::format("v{}", i);
           j["views"].push_back(v);
         }
       },
       "views; at most"},  // info: more than 4096; render (maps): more than 64

      {"format_wrong", [](json& j) { j["format"] = "other"; }, "\"format\" is not"},
      {"version_2", [](json& j) { j["version"] = 2; }, "unsupported version 2"},
      {"views_not_array", [](json& j) { j["views"] = 3; }, "\"views\" is not an array"},
      {"depth_file_missing", [](json& j) { j["views"][0]["depth"] = "depth/none.exr"; },
       "file does not exist"},
  };
  for (const Edit& e : edits) {
    const auto make_dataset = [e](const fs::path& dir) {
      DatasetWith(dir / "D", e.edit);
      return Quote(dir / "D");
    };
    add(
        "info_" + e.name,
        [=](const fs::path& dir, const fs::path&) { return "info " + make_dataset(dir); },
        e.expect);
    add(
        "render_" + e.name,
        [=](const fs::path& dir, const fs::path& out) {
          return "render " + make_dataset(dir) + " --orbit 1 --size 16 --out " + Quote(out);
        },
        e.expect);
  }
  // The map limit (ibr::kMaxMaps, 4096 = the dataset view limit) on the
  // manifest: its images do not exist, so any other error would mean one was
  // looked for first.
  for (const int views : {4097, 100000}) {
    add(
        fmt::format("render_{}_views_as_maps", views),
        [views](const fs::path& dir, const fs::path& out) {
          DatasetWith(dir / "D", [views](json& j) {
            json v = j["views"][0];
            j["views"] = json::array();
            for (int i = 0; i < views; ++i) {
              v["name"] = fmt::format("v{}", i);
              v["color"] = fmt::format("color/none{}.png", i);
              j["views"].push_back(v);
            }
          });
          return "render " + Quote(dir / "D") + " --orbit 1 --size 16 --out " + Quote(out);
        },
        "dataset.json': more than 4096 views; at most 4096 are supported");
  }
  // Export takes perspective datasets: a few of the edits through it too.
  for (const Edit& e : {edits[0], edits[5], edits[21], edits[25]}) {
    add(
        "export_" + e.name,
        [=](const fs::path& dir, const fs::path& out) {
          DatasetWith(dir / "D", e.edit, GetFixtures().persp);
          return "export colmap " + Quote(dir / "D") + " --out " + Quote(out);
        },
        e.expect);
  }

  // -- dataset files (render loads every image)
  auto file_case = [&](std::string name, std::function<void(const fs::path& d)> damage,
                       std::string expect) {
    add(
        "render_" + name,
        [=](const fs::path& dir, const fs::path& out) {
          DatasetWith(dir / "D", [](json&) {});
          damage(dir / "D");
          return "render " + Quote(dir / "D") + " --orbit 1 --size 16 --out " + Quote(out);
        },
        expect);
  };
  file_case(
      "manifest_not_json", [](const fs::path& d) { Spit(d / "dataset.json", "{\"format\": "); },
      "not valid JSON");
  file_case(
      "manifest_empty", [](const fs::path& d) { Spit(d / "dataset.json", ""); }, "not valid JSON");
  file_case(
      "manifest_missing", [](const fs::path& d) { fs::remove(d / "dataset.json"); },
      "has no dataset.json");
  file_case(
      "depth_is_png",
      [](const fs::path& d) {
        const json j = json::parse(Slurp(d / "dataset.json"));
        fs::copy_file(d / j["views"][0]["mask"].get<std::string>(),
                      d / j["views"][0]["depth"].get<std::string>(),
                      fs::copy_options::overwrite_existing);
      },
      "is a png file, not the openexr");
  file_case(
      "color_truncated_png",
      [](const fs::path& d) {
        const json j = json::parse(Slurp(d / "dataset.json"));
        const fs::path p = d / j["views"][0]["color"].get<std::string>();
        const std::string bytes = Slurp(p);
        Spit(p, bytes.substr(0, bytes.size() / 2));
      },
      "truncated PNG (ends inside chunk IDAT)");
  file_case(
      "color_truncated_jpeg",
      [](const fs::path& d) {
        json j = json::parse(Slurp(d / "dataset.json"));
        const core::Image8 c =
            core::ReadImage<uint8_t>(d / j["views"][0]["color"].get<std::string>());
        core::WriteImage(d / "color" / "v0.jpg", c);
        const std::string bytes = Slurp(d / "color" / "v0.jpg");
        Spit(d / "color" / "v0.jpg", bytes.substr(0, bytes.size() * 2 / 3));
        j["views"][0]["color"] = "color/v0.jpg";
        Spit(d / "dataset.json", j.dump());
      },
      "truncated JPEG");
  file_case(
      "color_wrong_size",
      [](const fs::path& d) {
        const json j = json::parse(Slurp(d / "dataset.json"));
        core::WriteImage(d / j["views"][0]["color"].get<std::string>(), core::Image8(8, 8, 3, 0));
      },
      "image is 8x8, camera 1 is 32x32");
  file_case(
      "color_claims_16385px",
      [](const fs::path& d) {
        const json j = json::parse(Slurp(d / "dataset.json"));
        const fs::path p = d / j["views"][0]["color"].get<std::string>();
        Spit(p, PngWithClaimedSize(Slurp(p), 16385, 16000));
      },
      "the limit is 16384 pixels a side and 4 channels");
  file_case(
      "color_is_text",
      [](const fs::path& d) {
        const json j = json::parse(Slurp(d / "dataset.json"));
        Spit(d / j["views"][0]["color"].get<std::string>(), "hello");
      },
      "cannot decode image");
  file_case(
      "depth_1e30",
      [](const fs::path& d) {
        const json j = json::parse(Slurp(d / "dataset.json"));
        core::WriteImage(d / j["views"][0]["depth"].get<std::string>(),
                         core::ImageF(32, 32, 1, 1e30f));
      },
      "depth 1e+30 is beyond");
  file_case(
      "depth_negative",
      [](const fs::path& d) {
        const json j = json::parse(Slurp(d / "dataset.json"));
        core::WriteImage(d / j["views"][0]["depth"].get<std::string>(),
                         core::ImageF(32, 32, 1, -1.f));
      },
      "negative depth");
  file_case(
      "depth_three_channels",
      [](const fs::path& d) {
        const json j = json::parse(Slurp(d / "dataset.json"));
        core::WriteImage(d / j["views"][0]["depth"].get<std::string>(),
                         core::ImageF(32, 32, 3, 1.f));
      },
      "expected 1 channel(s), file has 3");
  add(
      "render_dataset_is_file",
      [](const fs::path& dir, const fs::path& out) {
        Spit(dir / "D", "x");
        return "render " + Quote(dir / "D") + " --orbit 1 --out " + Quote(out);
      },
      "is not a dataset (a folder with dataset.json)");
  add("render_dataset_missing", fixed("render /nonexistent-ibr --orbit 1 --out OUT"),
      "does not exist");
  // A volume, a mesh or a scene where a dataset goes: named, with its command,
  // before any other complaint (no --orbit here: that is not the problem).
  add(
      "render_volume",
      [](const fs::path& dir, const fs::path& out) {
        Spit(dir / "scan.nhdr", "NRRD0004\ntype: uchar\n");
        return "render " + Quote(dir / "scan.nhdr") + " --out " + Quote(out);
      },
      "is a volume (NRRD), not a dataset: `ibr volume scan.nhdr` renders it");
  add(
      "info_mesh",
      [](const fs::path& dir, const fs::path&) {
        Spit(dir / "mesh.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
        return "info " + Quote(dir / "mesh.obj");
      },
      "is a mesh (obj), not a dataset: `ibr capture --mesh mesh.obj --out DIR`");
  add(
      "view_volume",
      [](const fs::path& dir, const fs::path&) {
        Spit(dir / "scan.nhdr", "NRRD0004\ntype: uchar\n");
        return "view " + Quote(dir / "scan.nhdr") + " --screenshot " + Quote(dir / "s.png");
      },
      "is a volume (NRRD), not a dataset");
  add(
      "render_manifest_itself",
      [](const fs::path& dir, const fs::path& out) {
        DatasetWith(dir / "D", [](json&) {});
        return "render " + Quote(dir / "D" / "dataset.json") + " --orbit 1 --out " + Quote(out);
      },
      "is a dataset's manifest: give its folder");
  add(
      "bench_out_missing_folder",
      [](const fs::path& dir, const fs::path&) {
        return "bench viewer --quick --csv " + Quote(dir / "v.csv") + " --out " +
               Quote(dir / "plots");
      },
      "no such folder (the plots go into a folder that exists");
  add("typo_flag_suggests", fixed("render CUBE --orbti 4 --out OUT"),
      "'ibr render' has no option '--orbti'; did you mean '--orbit'?", kCli);

  // -- render options
  for (const auto& [name, args, expect] :
       std::vector<std::tuple<std::string, std::string, std::string>>{
           {"slices_zero", "--orbit 1 --slices 0", "slices"},
           {"slices_negative", "--orbit 1 --slices -5", "slices"},
           {"method_bogus", "--orbit 1 --method bogus",
            "--method: unknown method 'bogus' (depth-object, visual-hull)"},
           {"slicing_bogus", "--orbit 1 --slicing bogus", "bogus"},
           {"texturing_bogus", "--orbit 1 --texturing bogus", "bogus"},
           {"outside_bogus", "--orbit 1 --outside maybe",
            "--outside: unknown policy 'maybe' (pass, fail)"},
           {"invalid_depth_bogus", "--orbit 1 --invalid-depth maybe",
            "--invalid-depth: unknown policy 'maybe' (empty, no-constraint)"},
           {"robust_negative", "--orbit 1 --robust -1", "robust"},
           {"orbit_zero", "--orbit 0", "give exactly one of --cameras"},
           {"orbit_and_cameras", "--orbit 2 --cameras " + cube, "give exactly one of --cameras"},
           {"size_huge", "--orbit 1 --size 100000",
            "--size: a 100000x100000 frame is larger than this GL implementation's largest"},
           {"cameras_size_huge", "--cameras RING --size 20000",
            "--size: a 20000x20000 frame is larger than"},
           {"size_negative", "--orbit 1 --size -3", "--size -3"},
           {"cameras_missing", "--cameras /nonexistent-ibr", "--cameras: does not exist"},
           {"truth_mesh_missing", "--orbit 1 --size 16 --truth-mesh /nonexistent-ibr.obj",
            "file does not exist"},
       }) {
    add("render_" + name, fixed("render CUBE " + args + " --out OUT"), expect);
  }
  add(
      "render_truth_mesh_zero_extent",
      [=](const fs::path& dir, const fs::path& out) {
        Spit(dir / "point.obj", "v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\n");
        return "render " + Quote(GetFixtures().dataset) + " --orbit 1 --size 16 --truth-mesh " +
               Quote(dir / "point.obj") + " --out " + Quote(out);
      },
      "mesh has no extent");
  // A frame over the memory budget (--memory-budget, before the subcommand).
  add("render_size_over_budget",
      fixed("--memory-budget=1536M render CUBE --orbit 1 --size 9000 --out OUT"),
      "--size: a 9000x9000 frame (48 bytes per pixel with its readback) needs 3.62 GiB, over the "
      "memory budget of 1.50 GiB");
  add("capture_size_over_budget",
      fixed("--memory-budget=1536M capture --shape sphere --size 8200 --out OUT"),
      "--size: a 8200x8200 frame (48 bytes per pixel with its readback) needs 3.01 GiB, over the "
      "memory budget of 1.50 GiB");
  add("render_size_not_integer", fixed("render " + cube + " --orbit 1 --size 64.5 --out OUT"),
      "--size", kCli);

  // -- capture options and meshes
  for (const auto& [name, args, expect, code] :
       std::vector<std::tuple<std::string, std::string, std::string, int>>{
           {"size_zero", "--shape sphere --size 0", "--size: a 0x0 frame is empty", 1},
           {"size_64_5", "--shape sphere --size 64.5", "--size", kCli},
           {"size_huge", "--shape sphere --size 100000",
            "--size: a 100000x100000 frame is larger than this GL implementation's largest", 1},
           {"rig_bogus", "--shape sphere --rig bogus", "bogus", 1},
           {"rig_ring_zero", "--shape sphere --rig ring:0", "ring:0", 1},
           {"rig_sphere_huge", "--shape sphere --rig sphere:100000", "sphere:100000", 1},
           {"shape_bogus", "--shape blob", "blob", 1},
           {"mesh_and_shape", "--shape sphere --mesh x.obj", "exactly one of", 1},
           {"nothing_to_capture", "--rig cube", "exactly one of", 1},
           {"mesh_missing", "--mesh /nonexistent-ibr.obj", "file does not exist", 1},
           {"mesh_is_folder", "--mesh /tmp", "is a folder, not a mesh file", 1},
           {"fov_zero", "--shape sphere --rig ring:4 --fov 0", "fov", 1},
           {"fov_180", "--shape sphere --rig ring:4 --fov 180", "fov", 1},
           {"fov_nan", "--shape sphere --rig ring:4 --fov nan", "fov", 1},
           {"scene_bogus", "--scene nope", "nope", 1},
           {"background_bogus", "--shape sphere --background plaid", "--background", kCli},
           {"texture_with_shape", "--shape sphere --texture /nonexistent-ibr.png",
            "--texture applies to --mesh only", 1},
       }) {
    add(
        "capture_" + name,
        [args = args](const fs::path&, const fs::path& out) {
          return "capture " + args + " --out " + Quote(out);
        },
        expect, code);
  }
  add(
      "capture_mesh_zero_extent",
      [](const fs::path& dir, const fs::path& out) {
        Spit(dir / "point.obj", "v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\n");
        return "capture --mesh " + Quote(dir / "point.obj") + " --rig cube --size 16 --out " +
               Quote(out);
      },
      "mesh has no extent");
  add(
      "capture_mesh_garbage",
      [](const fs::path& dir, const fs::path& out) {
        Spit(dir / "junk.obj", std::string("\x01\x02garbage\xff", 11));
        return "capture --mesh " + Quote(dir / "junk.obj") + " --rig cube --size 16 --out " +
               Quote(out);
      },
      "junk.obj");
  add(
      "capture_mesh_1e38",
      [](const fs::path& dir, const fs::path& out) {
        Spit(dir / "far.obj", "v 0 0 0\nv 1e38 0 0\nv 0 1e38 0\nf 1 2 3\n");
        return "capture --mesh " + Quote(dir / "far.obj") + " --rig cube --size 16 --out " +
               Quote(out);
      },
      "far.obj");

  // -- import
  add("import_colmap_missing", fixed("import colmap /nonexistent-ibr --out OUT"),
      "nonexistent-ibr");
  add(
      "import_colmap_empty",
      [](const fs::path& dir, const fs::path& out) {
        fs::create_directories(dir / "ws");
        return "import colmap " + Quote(dir / "ws") + " --out " + Quote(out);
      },
      "ws");
  add("import_colmap_input_type", fixed("import colmap /tmp --input-type bogus --out OUT"),
      "bogus");
  add("import_redwood_missing", fixed("import redwood /nonexistent-ibr --out OUT"),
      "nonexistent-ibr");
  add(
      "import_redwood_garbage_log",
      [](const fs::path& dir, const fs::path& out) {
        Spit(dir / "rw" / "trajectory.log", "0 0 1\n1 0 0 0\nnot numbers\n");
        return "import redwood " + Quote(dir / "rw") + " --out " + Quote(out);
      },
      "rw");
  add("import_redwood_depth_scale_zero", fixed("import redwood /tmp --depth-scale 0 --out OUT"),
      "depth-scale");
  add("import_redwood_depth_scale_1e30", fixed("import redwood /tmp --depth-scale 1e30 --out OUT"),
      "depth-scale");
  add("import_middlebury_missing", fixed("import middlebury /nonexistent-ibr --out OUT"),
      "nonexistent-ibr");
  add(
      "import_middlebury_garbage_par",
      [](const fs::path& dir, const fs::path& out) {
        Spit(dir / "mb" / "ring_par.txt", "2\nimg.png 1 2 3\n");
        return "import middlebury " + Quote(dir / "mb") + " --out " + Quote(out);
      },
      "ring_par.txt");
  add("import_middlebury_threshold", fixed("import middlebury /tmp --threshold 2 --out OUT"),
      "threshold");

  // -- export
  add("export_missing", fixed("export colmap /nonexistent-ibr --out OUT"), "does not exist");
  add("export_orthographic", fixed("export colmap " + cube + " --out OUT"), "orthographic");
  add(
      "export_point_step_zero",
      [](const fs::path&, const fs::path& out) {
        return "export colmap " + Quote(GetFixtures().persp) + " --point-step 0 --out " +
               Quote(out);
      },
      "point_step_px 0 outside");

  // -- info, displace, demo, bench
  add("info_missing", fixed("info /nonexistent-ibr"), "does not exist");
  add("displace_method_bogus", fixed("displace --method bogus --out /tmp/ibr-never.png"), "bogus");
  add("displace_slices_zero", fixed("displace --slices 0 --out /tmp/ibr-never.png"), "slices");
  add("displace_size_huge", fixed("displace --size 100000 --out /tmp/ibr-never.png"), "size");
  add("displace_base_bogus", fixed("displace --base cone --out /tmp/ibr-never.png"), "cone");
  add("displace_height_bogus", fixed("displace --height waves --out /tmp/ibr-never.png"), "waves");
  add("displace_tiling_zero", fixed("displace --tiling 0 --out /tmp/ibr-never.png"), "tiling");
  add("demo_size_tiny", fixed("demo --size 3 --out OUT"), "--size");
  // --size of every other command through the one frame-size check.
  add("displace_size_over_budget",
      fixed("--memory-budget=1536M displace --size 9000 --out /tmp/ibr-never.png"),
      "--size: a 9000x9000 frame (48 bytes per pixel with its readback) needs 3.62 GiB, over the "
      "memory budget of 1.50 GiB");
  add("demo_size_huge", fixed("demo --size 20000 --out OUT"),
      "--size: a 20000x20000 frame is larger than");
  add("deform_size_over_budget",
      fixed(
          "--memory-budget=1536M deform /nonexistent-ibr.obj --size 9000 --out /tmp/ibr-never.png"),
      "--size: a 9000x9000 frame (48 bytes per pixel with its readback) needs 3.62 GiB, over the "
      "memory budget of 1.50 GiB");
  add("volume_size_huge", fixed("volume /nonexistent-ibr.nrrd --size 20000 --out OUT"),
      "--size: a 20000x20000 frame is larger than");
  add("bench_fillrate_size_over_budget", fixed("--memory-budget=1536M bench fillrate --size 9000"),
      "--size: a 9000x9000 frame (48 bytes per pixel with its readback) needs 3.62 GiB, over the "
      "memory budget of 1.50 GiB");
  add("bench_ncs_size_huge", fixed("bench ncs --csv OUT --size 20000"),
      "--size: a 20000x20000 frame is larger than");
  add("bench_scene_size_over_budget",
      fixed("--memory-budget=1536M bench scene --csv OUT --size 9000"),
      "--size: a 9000x9000 frame (48 bytes per pixel with its readback) needs 3.62 GiB, over the "
      "memory budget of 1.50 GiB");
  add("bench_volume_size_huge", fixed("bench volume --csv OUT --size 20000"),
      "--size: a 20000x20000 frame is larger than");
  add("bench_depth_object_sizes_huge", fixed("bench depth-object --csv OUT --sizes 128 20000"),
      "--sizes: a 20000x20000 frame is larger than");
  add("bench_displacement_no_csv", fixed("bench displacement --out OUT"), "--csv", kCli);
  add("bench_kautz_seidel_bad_object", fixed("bench kautz-seidel --csv OUT --object nosuch"),
      "--object 'nosuch'");
  add("bench_fillrate_bogus_flag", fixed("bench fillrate --bogus"), "--bogus", kCli);
  return cases;
}

class BadInput : public ::testing::TestWithParam<Case> {};

TEST_P(BadInput, OneLineNonZeroInputsUntouchedNothingWritten) {
  const Case& c = GetParam();
  const fs::path dir = test_support::TestOutputDir() / "case";
  const fs::path out = test_support::TestOutputDir() / "out";
  fs::create_directories(dir);
  const std::string args = c.make(dir, out);
  const auto fixtures_before = Snapshot(GetFixtures().root);
  const auto inputs_before = Snapshot(dir);
  const auto r = RunCommand(IbrBinary() + " --log-level error " + args);
  if (c.exit_code == kCli) {
    EXPECT_GE(r.exit_code, 100) << args << "\n" << r.err;
    EXPECT_LE(r.exit_code, 120) << args << "\n" << r.err;
  } else {
    EXPECT_EQ(r.exit_code, c.exit_code) << args << "\n" << r.err;
  }
  EXPECT_EQ(CountLines(r.err), 1) << args << "\n" << r.err;
  EXPECT_EQ(r.err.rfind("ibr: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(c.expect), std::string::npos)
      << "expected '" << c.expect << "' in: " << r.err;
  EXPECT_EQ(Snapshot(dir), inputs_before) << "inputs changed by: " << args;
  EXPECT_EQ(Snapshot(GetFixtures().root), fixtures_before) << "fixtures changed by: " << args;
  EXPECT_FALSE(fs::exists(fs::symlink_status(out))) << "output left at " << out;
  for (const auto& e : fs::directory_iterator(out.parent_path())) {
    const std::string name = e.path().filename().string();
    EXPECT_EQ(name.find(".tmp-"), std::string::npos) << "staging left behind: " << name;
  }
}

INSTANTIATE_TEST_SUITE_P(Corpus, BadInput, ::testing::ValuesIn(Corpus()),
                         [](const ::testing::TestParamInfo<Case>& p) {
                           std::string name = p.param.name;  // gtest names: letters, digits, _
                           for (char& c : name)
                             c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
                           return name;
                         });

TEST(BadInputCorpus, HasAtLeast80Cases) { EXPECT_GE(Corpus().size(), 80u); }

// ---- Signals -------------------------------------------------------------------

// Starts `ibr args...` with stdout/stderr to /dev/null; returns its pid.
pid_t Spawn(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  const std::string binary = IbrBinary();
  argv.push_back(const_cast<char*>(binary.c_str()));
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, binary.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return rc == 0 ? pid : -1;
}

// True once a staging folder of `out` holds a file (the capture is under way).
bool StagingHasFiles(const fs::path& out) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(out.parent_path(), ec)) {
    if (e.path().filename().string().rfind("." + out.filename().string() + ".tmp-", 0) != 0)
      continue;
    for (const auto& f : fs::recursive_directory_iterator(e.path(), ec)) {
      if (f.is_regular_file()) return true;
    }
  }
  return false;
}

// Interrupts a capture once it has written its first view; returns the wait status.
int InterruptCapture(const fs::path& out, int sig) {
  const pid_t pid = Spawn({"capture", "--shape", "sphere", "--rig", "sphere:40", "--size", "256",
                           "--out", out.string()});
  EXPECT_GT(pid, 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (!StagingHasFiles(out) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_TRUE(StagingHasFiles(out)) << "the capture never started writing";
  ::kill(pid, sig);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return status;
}

class Signals : public ::testing::TestWithParam<int> {};

TEST_P(Signals, CaptureInterruptedLeavesNothingAndUserFolderSurvives) {
  const int sig = GetParam();
  const fs::path root = test_support::TestOutputDir();
  Spit(root / "Documents" / "letter.txt", "dear");
  const auto before = Snapshot(root);
  const int status = InterruptCapture(root / "out", sig);
  EXPECT_TRUE(WIFSIGNALED(status)) << "status " << status;
  if (WIFSIGNALED(status)) {
    EXPECT_EQ(WTERMSIG(status), sig);
  }
  EXPECT_EQ(Snapshot(root), before) << "something left behind (or removed) by signal " << sig;
}

INSTANTIATE_TEST_SUITE_P(Caught, Signals, ::testing::Values(SIGINT, SIGTERM, SIGHUP),
                         [](const ::testing::TestParamInfo<int>& p) {
                           return p.param == SIGINT    ? "SIGINT"
                                  : p.param == SIGTERM ? "SIGTERM"
                                                       : "SIGHUP";
                         });

TEST(Signals, KilledCaptureLeavesStagingThatTheNextRunRemoves) {
  const fs::path root = test_support::TestOutputDir();
  const fs::path out = root / "out";
  const int status = InterruptCapture(out, SIGKILL);
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_TRUE(StagingHasFiles(out)) << "SIGKILL cannot be caught: the staging folder stays";
  const auto r = RunCommand(
      IbrBinary() + " --log-level error capture --shape sphere --rig cube --size 16 --out " +
      Quote(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(root)) names.push_back(e.path().filename().string());
  EXPECT_EQ(names, std::vector<std::string>{"out"});
}

}  // namespace
