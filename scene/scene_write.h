// Writes a scene::Scene as the JSON that scene::ReadScene reads back
// (scene/scene.h): ReadScene(WriteScene(s)) equals s, field for field. The
// viewer saves the scene its edits produced with it (`ibr view --save-scene`).
//
// Generic over the objects' settings: every scene::Setting is written under
// its key as the value it holds (whatever the kind's key table allows), so a
// new effect key needs no change here. Files are written as absolute paths
// (the reader resolved them), or relative to `base_dir` when they lie under
// it; "shared_mesh" / "shared_volume" sources are written as the files they
// resolved to. Transforms are written as {"matrix": rows}, doubles with the
// digits that read back to the same bits. CPU only.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <ostream>

#include "scene/scene.h"

namespace scene {

struct WriteOptions {
  // Files under this folder are written relative to it (the folder of the
  // file being written, so the scene reads back from there); empty: absolute.
  std::filesystem::path base_dir;
};

// The document (version kSceneVersion).
nlohmann::json SceneToJson(const Scene& scene, const WriteOptions& options = {});
void WriteScene(std::ostream& out, const Scene& scene, const WriteOptions& options = {});
// Staged (core::AtomicWriteStream): no partial file on an error. base_dir is
// the file's folder.
void WriteScene(const std::filesystem::path& path, const Scene& scene);

}  // namespace scene
