// Safe output: write to a temporary sibling, then rename over the target, so a
// failed or interrupted run never leaves a half-written file behind, and never
// delete anything ibr did not write.
//
// The rules every output follows (StagedDirectory and AtomicWrite apply them):
// - an output never overlaps an input: not the same file or folder, not inside
//   an input folder, not a folder holding an input (NoteInputPath);
// - an output folder is created, or replaces an empty folder, or replaces an
//   earlier ibr output whose files are all listed in its `.ibr-output` marker;
//   any other existing folder is refused (there is no override: ibr never
//   deletes a file it did not write);
// - an existing single file is replaced only when ibr wrote it: it carries
//   kFileMark where its format keeps text (a PNG/EXR/TIFF/JPEG `Software`
//   attribute, a PLY `comment`, a `#` line of OBJ, MTL, NRRD), or the
//   kOutputMarker of its folder lists it; any other file (a CSV or JSON of
//   the user's, say) is refused unless the command line says --overwrite
//   (SetOverwriteFiles). Replacing prints one line saying so;
// - staging names are `.NAME.tmp-PID-N`; they are removed on error (destructor),
//   on SIGINT/SIGTERM/SIGHUP/SIGABRT (InstallCleanupSignalHandlers), and those
//   of dead processes (a SIGKILL) by the next run writing to the same place.
#pragma once

#include <filesystem>
#include <functional>
#include <ostream>
#include <string>
#include <string_view>

namespace core {

// The marker written into every output folder: first line "ibr output: " +
// the command line (SetOutputDescription), then one line per file ibr wrote
// (relative, '/'-separated).
inline constexpr const char* kOutputMarker = ".ibr-output";

// The text every file ibr writes carries where its format has room for it.
inline constexpr const char* kFileMark = "written by ibr";

// What the marker's first line names (the CLI sets its command line).
void SetOutputDescription(std::string description);

// Records a path the running command reads (a file or a folder; the CLI notes
// every existing path given on its command line, readers note what they open).
// Outputs overlapping any noted input are refused.
void NoteInputPath(const std::filesystem::path& path);
void ClearInputPaths();  // for tests

// InputError("where: 'output': ...") if `output` is, is inside, or contains a
// noted input (compared by device and inode through every ancestor, so
// symlinks, `..` and hard links to folders do not hide an overlap).
void CheckNotAnInput(std::string_view where, const std::filesystem::path& output);

// InputError unless `dir` may be replaced by a new output: it does not exist,
// or is an empty folder, or holds only files listed in its kOutputMarker.
void CheckReplaceableOutput(std::string_view where, const std::filesystem::path& dir);

// True if `path` is a regular file ibr wrote: it carries kFileMark (see the
// rules above), or its folder's kOutputMarker lists it.
bool IsIbrOutputFile(const std::filesystem::path& path);

// --overwrite: existing files that ibr did not write may be replaced too.
void SetOverwriteFiles(bool overwrite);

// InputError("where: 'path': ...") unless `path` may be written as a single
// file: it does not exist, or it is a regular file ibr wrote (or
// --overwrite was given); never a folder or a symbolic link. Prints the
// line that says an earlier output is replaced when `announce` is set.
void CheckReplaceableFile(std::string_view where, const std::filesystem::path& path,
                          bool announce = false);

// Removes staging siblings `.NAME.tmp-PID-N` of `path` left by processes that
// no longer run (killed by SIGKILL or power loss). Never touches those of
// live processes.
void RemoveStaleStaging(const std::filesystem::path& path);

// SIGINT, SIGTERM, SIGHUP and SIGABRT remove every live staging path (with
// async-signal-safe calls only) and then re-raise the signal with its default
// action, so the exit status still says which signal ended the process.
// Call it from the thread that writes the outputs (main): a signal another
// thread receives is handed to that thread.
void InstallCleanupSignalHandlers();

// What AtomicWrite may do with a file already at `path`: replace it only if
// ibr wrote it (CheckReplaceableFile; every output a user names), or always
// (ibr's own cache files, which no user names).
enum class ExistingFile { kIbrOutputOnly, kReplace };

// Calls write(tmp_path) and renames tmp_path to `path` if it returns without
// throwing; removes tmp_path otherwise. The parent directory must exist.
// `path` must not be a noted input. Inside a staging folder nothing exists
// yet to be checked.
void AtomicWrite(const std::filesystem::path& path,
                 const std::function<void(const std::filesystem::path& tmp_path)>& write,
                 ExistingFile existing = ExistingFile::kIbrOutputOnly);

// Stream flavour: write(stream) into a binary ofstream on a temporary file.
void AtomicWriteStream(const std::filesystem::path& path,
                       const std::function<void(std::ostream& out)>& write,
                       ExistingFile existing = ExistingFile::kIbrOutputOnly);

// A directory populated under a temporary name and renamed into place by
// Commit(); the destructor (or a signal) removes it if Commit() was never
// reached. Used by commands that write several files (a dataset, a render) so
// that failure leaves no partial output. Commit() writes kOutputMarker.
class StagedDirectory {
 public:
  // Fails (InputError) if `final_path` overlaps a noted input, is a file, or
  // is a folder CheckReplaceableOutput refuses; with `overwrite` false, also
  // if it is an earlier output (not empty).
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
  int cleanup_slot_ = -1;
  bool committed_ = false;
};

}  // namespace core
