// Atomic output: write to a temporary sibling, then rename over the target,
// so a failed run never leaves a half-written file behind.
#pragma once

#include <filesystem>
#include <functional>
#include <ostream>

namespace core {

// Calls write(tmp_path) and renames tmp_path to `path` if it returns without
// throwing; removes tmp_path otherwise. The parent directory must exist.
void AtomicWrite(const std::filesystem::path& path,
                 const std::function<void(const std::filesystem::path& tmp_path)>& write);

// Stream flavour: write(stream) into a binary ofstream on a temporary file.
void AtomicWriteStream(const std::filesystem::path& path,
                       const std::function<void(std::ostream& out)>& write);

// A directory populated under a temporary name and renamed into place by
// Commit(); the destructor removes it if Commit() was never reached. Used by
// commands that write several files (a dataset, a render) so that failure
// leaves no partial output.
class StagedDirectory {
 public:
  // Fails (InputError) if `final_path` exists and is a non-empty directory and
  // `overwrite` is false.
  explicit StagedDirectory(std::filesystem::path final_path, bool overwrite = true);
  ~StagedDirectory();
  StagedDirectory(const StagedDirectory&) = delete;
  StagedDirectory& operator=(const StagedDirectory&) = delete;

  // Where to write files now.
  const std::filesystem::path& path() const { return staging_path_; }
  const std::filesystem::path& final_path() const { return final_path_; }
  void Commit();

 private:
  std::filesystem::path final_path_;
  std::filesystem::path staging_path_;
  bool committed_ = false;
};

}  // namespace core
