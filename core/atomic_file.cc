#include "core/atomic_file.h"

#include <atomic>
#include <fstream>
#include <random>
#include <system_error>

#include <unistd.h>

#include "core/check.h"
#include "core/error.h"

namespace core {
namespace fs = std::filesystem;

namespace {

// A sibling name unique within this process and across processes.
fs::path TemporarySibling(const fs::path& path) {
  static std::atomic<unsigned> counter{0};
  return path.parent_path() /
         fmt::format(".{}.tmp-{}-{}", path.filename().string(), ::getpid(), counter++);
}

}  // namespace

void AtomicWrite(const fs::path& path, const std::function<void(const fs::path&)>& write) {
  const fs::path parent = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  if (!fs::is_directory(parent)) {
    ThrowFileError("AtomicWrite", path, "parent directory does not exist");
  }
  const fs::path tmp = TemporarySibling(path);
  try {
    write(tmp);
  } catch (...) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw;
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    ThrowFileError("AtomicWrite", path, "cannot rename temporary file into place");
  }
}

void AtomicWriteStream(const fs::path& path, const std::function<void(std::ostream&)>& write) {
  AtomicWrite(path, [&](const fs::path& tmp) {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) ThrowFileError("AtomicWriteStream", path, "cannot open for writing");
    write(out);
    out.flush();
    if (!out) ThrowFileError("AtomicWriteStream", path, "write failed");
  });
}

StagedDirectory::StagedDirectory(fs::path final_path, bool overwrite)
    : final_path_(std::move(final_path)) {
  if (final_path_.filename().empty()) final_path_ = final_path_.parent_path();
  if (fs::exists(final_path_) && !fs::is_directory(final_path_)) {
    ThrowFileError("StagedDirectory", final_path_, "exists and is not a directory");
  }
  if (!overwrite && fs::is_directory(final_path_) && !fs::is_empty(final_path_)) {
    ThrowFileError("StagedDirectory", final_path_, "exists and is not empty");
  }
  const fs::path parent = final_path_.parent_path().empty() ? fs::path(".") : final_path_.parent_path();
  std::error_code ec;
  fs::create_directories(parent, ec);
  if (ec) ThrowFileError("StagedDirectory", parent, "cannot create directory: {}", ec.message());
  staging_path_ = TemporarySibling(final_path_);
  fs::create_directory(staging_path_, ec);
  if (ec) ThrowFileError("StagedDirectory", staging_path_, "cannot create: {}", ec.message());
}

StagedDirectory::~StagedDirectory() {
  if (!committed_) {
    std::error_code ignored;
    fs::remove_all(staging_path_, ignored);
  }
}

void StagedDirectory::Commit() {
  IBR_CHECK(!committed_);
  std::error_code ec;
  if (fs::exists(final_path_)) {
    // Replace: move the old directory aside first so the swap is two renames.
    const fs::path old = TemporarySibling(final_path_);
    fs::rename(final_path_, old, ec);
    if (ec) ThrowFileError("StagedDirectory", final_path_, "cannot replace: {}", ec.message());
    fs::rename(staging_path_, final_path_, ec);
    if (ec) {
      fs::rename(old, final_path_);
      ThrowFileError("StagedDirectory", final_path_, "cannot move into place: {}", ec.message());
    }
    fs::remove_all(old, ec);
  } else {
    fs::rename(staging_path_, final_path_, ec);
    if (ec) ThrowFileError("StagedDirectory", final_path_, "cannot move into place: {}", ec.message());
  }
  committed_ = true;
}

}  // namespace core
