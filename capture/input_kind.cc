#include "capture/input_kind.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <system_error>

#include "core/error.h"

namespace capture {
namespace fs = std::filesystem;

namespace {

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

std::string Head(const fs::path& path, size_t bytes) {
  std::ifstream in(path, std::ios::binary);
  std::string head(bytes, '\0');
  in.read(head.data(), static_cast<std::streamsize>(bytes));
  head.resize(static_cast<size_t>(std::max<std::streamsize>(in.gcount(), 0)));
  return head;
}

bool EndsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// The format name of a volume file, or empty.
std::string VolumeFormat(const fs::path& path, const std::string& head) {
  const std::string name = Lower(path.filename().string());
  if (head.rfind("NRRD000", 0) == 0) return "NRRD";
  if (head.size() >= 348 && (head.compare(344, 3, "n+1") == 0 || head.compare(344, 3, "ni1") == 0))
    return "NIfTI-1";
  if (head.size() >= 544 && head.compare(4, 3, "n+2") == 0) return "NIfTI-2";
  if (EndsWith(name, ".nii") || EndsWith(name, ".nii.gz")) return "NIfTI";
  if (head.size() >= 132 && head.compare(128, 4, "DICM") == 0) return "DICOM";
  if (head.rfind("ObjectFileName", 0) == 0 || EndsWith(name, ".dat")) return "QVis";
  if (head.find("ObjectType = Image") != std::string::npos || EndsWith(name, ".mha") ||
      EndsWith(name, ".mhd"))
    return "MetaImage";
  if (EndsWith(name, ".nhdr") || EndsWith(name, ".nrrd")) return "NRRD";
  return {};
}

std::string MeshFormat(const fs::path& path, const std::string& head) {
  const std::string ext = Lower(path.extension().string());
  if (head.rfind("ply", 0) == 0 && head.size() > 3 && (head[3] == '\n' || head[3] == '\r'))
    return "PLY";
  if (head.rfind("glTF", 0) == 0) return "glTF binary";
  for (const char* e : {".obj", ".ply", ".stl", ".off", ".glb", ".gltf", ".fbx", ".dae", ".3ds"}) {
    if (ext == e) return Lower(std::string(e + 1)) == "glb" ? "glTF binary" : std::string(e + 1);
  }
  return {};
}

bool IsImage(const fs::path& path, const std::string& head) {
  if (head.rfind("\x89PNG", 0) == 0 || head.rfind("\xff\xd8\xff", 0) == 0) return true;
  if (head.rfind("\x76\x2f\x31\x01", 0) == 0) return true;  // OpenEXR
  const std::string ext = Lower(path.extension().string());
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".exr" || ext == ".tif" ||
         ext == ".tiff";
}

bool HasDicomFiles(const fs::path& dir) {
  std::error_code ec;
  int looked = 0;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end && looked < 16; it.increment(ec)) {
    if (!it->is_regular_file(ec)) continue;
    ++looked;
    const std::string head = Head(it->path(), 132);
    if (head.size() >= 132 && head.compare(128, 4, "DICM") == 0) return true;
  }
  return false;
}

}  // namespace

InputKind KindOfInput(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return InputKind::kMissing;
  if (fs::is_directory(path, ec)) {
    if (fs::is_regular_file(path / "dataset.json", ec)) return InputKind::kDataset;
    if (fs::exists(path / "sparse", ec) || fs::exists(path / "stereo", ec) ||
        fs::exists(path / "cameras.bin", ec) || fs::exists(path / "cameras.txt", ec))
      return InputKind::kColmap;
    if (fs::exists(path / "trajectory.log", ec) || fs::exists(path / "depth.txt", ec))
      return InputKind::kRgbd;
    if (HasDicomFiles(path)) return InputKind::kVolume;
    return InputKind::kOther;
  }
  const std::string head = Head(path, 1024);
  if (!VolumeFormat(path, head).empty()) return InputKind::kVolume;
  if (!MeshFormat(path, head).empty()) return InputKind::kMesh;
  if (IsImage(path, head)) return InputKind::kImage;
  if (Lower(path.extension().string()) == ".json") {
    // Scene files name objects; manifests name views.
    const std::string text = Head(path, 1 << 16);
    if (text.find("\"objects\"") != std::string::npos) return InputKind::kScene;
    if (text.find("\"views\"") != std::string::npos) return InputKind::kManifest;
  }
  return InputKind::kOther;
}

std::string WhatCommandTakes(const fs::path& path) {
  const std::string head = fs::is_regular_file(path) ? Head(path, 1024) : std::string();
  switch (KindOfInput(path)) {
    case InputKind::kMissing:
    case InputKind::kDataset:
      return {};
    case InputKind::kManifest:
      return fmt::format("is a dataset's manifest: give its folder '{}'",
                         path.parent_path().empty() ? "." : path.parent_path().string());
    case InputKind::kScene:
      return "is a scene file: `ibr render SCENE.json --out DIR` or `ibr view SCENE.json` draws "
             "it";
    case InputKind::kVolume: {
      const std::string format =
          fs::is_directory(path) ? std::string("a DICOM series") : VolumeFormat(path, head);
      return fmt::format("is a volume ({}), not a dataset: `ibr volume {}` renders it", format,
                         path.filename().string());
    }
    case InputKind::kMesh:
      return fmt::format(
          "is a mesh ({}), not a dataset: `ibr capture --mesh {} --out DIR` makes a dataset of "
          "it, `ibr deform` and `ibr displace --mesh` render it",
          MeshFormat(path, head), path.filename().string());
    case InputKind::kImage:
      return "is an image, not a dataset (a folder with dataset.json): `ibr capture` or `ibr "
             "import` makes one";
    case InputKind::kColmap:
      return "is a COLMAP workspace, not a dataset: `ibr import colmap DIR --out DATASET` "
             "reads it";
    case InputKind::kRgbd:
      return "is RGB-D frames, not a dataset: `ibr import redwood DIR --out DATASET` reads "
             "the Redwood layout";
    case InputKind::kOther:
      break;
  }
  return fs::is_directory(path) ? "has no dataset.json (not a dataset: `ibr capture` or `ibr "
                                  "import` makes one)"
                                : "is not a dataset (a folder with dataset.json) nor a scene "
                                  "file";
}

void CheckDatasetInput(std::string_view where, const fs::path& path, bool scene_ok) {
  const InputKind kind = KindOfInput(path);
  if (kind == InputKind::kDataset || (scene_ok && kind == InputKind::kScene)) return;
  // Any other JSON but a manifest goes to the scene reader, which says
  // what is wrong with it.
  if (scene_ok && kind != InputKind::kManifest && Lower(path.extension().string()) == ".json")
    return;
  if (kind == InputKind::kMissing) core::ThrowFileError(where, path, "does not exist");
  core::ThrowFileError(where, path, "{}", WhatCommandTakes(path));
}

}  // namespace capture
