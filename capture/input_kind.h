// What a path a user gave is, judged by its content, and which command takes
// it: so that `ibr render scan.nhdr` or `ibr info mesh.obj` says "a volume
// (NRRD): `ibr volume` renders it" instead of "not a directory".
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace capture {

enum class InputKind {
  kMissing,
  kDataset,   // a folder with dataset.json
  kManifest,  // dataset.json itself
  kScene,     // a scene file (JSON with "objects")
  kVolume,    // NRRD, NIfTI, QVis, MetaImage, a DICOM file or series folder
  kMesh,      // OBJ, PLY, STL, OFF, glTF/GLB, FBX, DAE
  kImage,     // PNG, JPEG, EXR, TIFF
  kColmap,    // a COLMAP workspace or sparse model folder
  kRgbd,      // Redwood or TUM RGB-D frames
  kOther,
};

// Sniffs `path`: magic bytes first (NRRD0, DICM, n+1, ply, glTF), then the
// folder's layout, then the extension.
InputKind KindOfInput(const std::filesystem::path& path);

// "a volume (NRRD): `ibr volume FILE` renders it", for every kind but
// kDataset and kMissing (empty for those).
std::string WhatCommandTakes(const std::filesystem::path& path);

// InputError("where: 'path': is a volume (NRRD) ...") unless `path` is a
// dataset folder (or, with `scene_ok`, a scene file); a missing path is
// "does not exist".
void CheckDatasetInput(std::string_view where, const std::filesystem::path& path, bool scene_ok);

}  // namespace capture
