#include "core/atomic_file.h"

#include <OpenImageIO/imageio.h>
#include <dirent.h>
#include <fcntl.h>
#include <pthread.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <climits>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <mutex>
#include <set>
#include <system_error>
#include <vector>

#include "core/check.h"
#include "core/error.h"

namespace core {
namespace fs = std::filesystem;

namespace {

// ---- Paths to remove if a signal ends the process -------------------------
// A fixed table (no allocation, readable from a signal handler): a slot is
// free (0), being filled (1) or live (2).
constexpr int kCleanupSlots = 64;
struct CleanupSlot {
  std::atomic<int> state{0};
  char path[PATH_MAX];
};
CleanupSlot g_cleanup[kCleanupSlots];

int RegisterCleanup(const fs::path& path) {
  std::error_code ec;
  const std::string s = fs::absolute(path, ec).string();
  if (ec || s.size() + 1 > sizeof(CleanupSlot::path)) return -1;
  for (int i = 0; i < kCleanupSlots; ++i) {
    int expected = 0;
    if (g_cleanup[i].state.compare_exchange_strong(expected, 1)) {
      std::memcpy(g_cleanup[i].path, s.c_str(), s.size() + 1);
      g_cleanup[i].state.store(2, std::memory_order_release);
      return i;
    }
  }
  return -1;  // table full: the stale-staging sweep of the next run covers it
}

void ReleaseCleanup(int slot) {
  if (slot >= 0) g_cleanup[slot].state.store(0, std::memory_order_release);
}

// Removes `name` (relative to dirfd) and everything under it, with
// async-signal-safe calls only (openat, getdents64, unlinkat, close).
void RemoveTreeAt(int dirfd, const char* name, int depth) {
  if (::unlinkat(dirfd, name, 0) == 0 || errno == ENOENT) return;
  if (depth > 32) return;
  const int fd = ::openat(dirfd, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return;
  // Deleting while reading a directory may skip entries: rescan until a pass
  // finds nothing left but "." and "..".
  for (int pass = 0; pass < 8; ++pass) {
    bool found = false;
    ::lseek(fd, 0, SEEK_SET);
    alignas(8) char buffer[2048];
    for (;;) {
      const ssize_t n = ::getdents64(fd, buffer, sizeof buffer);
      if (n <= 0) break;
      for (ssize_t off = 0; off < n;) {
        const auto* entry = reinterpret_cast<const dirent64*>(buffer + off);
        off += entry->d_reclen;
        const char* child = entry->d_name;
        if (std::strcmp(child, ".") == 0 || std::strcmp(child, "..") == 0) continue;
        found = true;
        RemoveTreeAt(fd, child, depth + 1);
      }
    }
    if (!found) break;
  }
  ::close(fd);
  ::unlinkat(dirfd, name, AT_REMOVEDIR);
}

std::atomic<int> g_handling_signal{0};
pthread_t g_main_thread;
std::atomic<bool> g_main_thread_known{false};

extern "C" void CleanupOnSignal(int sig) {
  // A kill or Ctrl-C may land on any thread (a GL driver's workers too) while
  // the main thread goes on writing into the staging folders: removing them
  // from here would race those writes. The main thread takes the signal over,
  // so nothing is written while they are removed. An abort stays on the
  // thread that aborts, which cannot return.
  if (sig != SIGABRT && g_main_thread_known.load(std::memory_order_acquire) &&
      !pthread_equal(pthread_self(), g_main_thread) && pthread_kill(g_main_thread, sig) == 0) {
    return;
  }
  if (g_handling_signal.exchange(1) == 0) {
    for (CleanupSlot& slot : g_cleanup) {
      if (slot.state.load(std::memory_order_acquire) == 2) RemoveTreeAt(AT_FDCWD, slot.path, 0);
    }
  }
  // Default action, then re-raise: the signal is blocked while this handler
  // runs, so it is delivered (and ends the process) as the handler returns.
  struct sigaction dfl = {};
  dfl.sa_handler = SIG_DFL;
  sigemptyset(&dfl.sa_mask);
  ::sigaction(sig, &dfl, nullptr);
  ::raise(sig);
}

// ---- Inputs and the marker -------------------------------------------------
std::mutex g_mutex;
std::vector<fs::path> g_inputs;  // canonical
std::string g_description = "ibr";

fs::path Canonical(const fs::path& p) {
  std::error_code ec;
  fs::path c = fs::weakly_canonical(fs::absolute(p, ec), ec);
  return ec ? fs::absolute(p) : c;
}

bool Equivalent(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  const bool same = fs::equivalent(a, b, ec);
  return !ec && same;
}

// True if `p` or one of its ancestors is the same file system object as `q`.
bool AtOrInside(const fs::path& p, const fs::path& q) {
  for (fs::path a = p;; a = a.parent_path()) {
    if (Equivalent(a, q)) return true;
    if (a == a.parent_path() || a.empty()) return false;
  }
}

// Staging name parts: `.NAME.tmp-PID-N` -> PID (0 if `entry` is not one of
// `target`'s staging names).
long StagingPid(const std::string& entry, const std::string& target) {
  const std::string prefix = "." + target + ".tmp-";
  if (entry.size() <= prefix.size() || entry.compare(0, prefix.size(), prefix) != 0) return 0;
  const std::string rest = entry.substr(prefix.size());
  const size_t dash = rest.find('-');
  if (dash == 0 || dash == std::string::npos || dash + 1 == rest.size()) return 0;
  for (size_t i = 0; i < rest.size(); ++i) {
    if (i != dash && (rest[i] < '0' || rest[i] > '9')) return 0;
  }
  if (dash > 9) return 0;
  return std::stol(rest.substr(0, dash));
}

bool ProcessAlive(long pid) { return ::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH; }

// A sibling name unique within this process and across processes.
fs::path TemporarySibling(const fs::path& path) {
  static std::atomic<unsigned> counter{0};
  return path.parent_path() /
         fmt::format(".{}.tmp-{}-{}", path.filename().string(), ::getpid(), counter++);
}

// Regular files (and links, devices...) under `dir`, relative, '/'-separated.
std::vector<std::string> FilesUnder(const fs::path& dir) {
  std::vector<std::string> files;
  for (const fs::directory_entry& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_directory() || e.is_symlink())
      files.push_back(fs::relative(e.path(), dir).generic_string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::atomic<bool> g_overwrite_files{false};

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

bool IsStagingPath(const fs::path& p) { return p.string().find(".tmp-") != std::string::npos; }

// The first `limit` bytes of a text header, line by line, until `stop` (or
// the end): whether one of them contains kFileMark.
bool TextHeaderHasMark(const fs::path& path, const char* prefix, const char* stop, int max_lines) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  for (int n = 0; n < max_lines && std::getline(in, line); ++n) {
    if (line.size() > 4096) return false;
    if (line.rfind(prefix, 0) == 0 && line.find(kFileMark) != std::string::npos) return true;
    if (stop != nullptr && line.rfind(stop, 0) == 0) return false;
  }
  return false;
}

bool ListedInFolderMarker(const fs::path& path) {
  const fs::path dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  std::ifstream marker(dir / kOutputMarker);
  std::string line;
  if (!marker || !std::getline(marker, line) || line.rfind("ibr output:", 0) != 0) return false;
  const std::string name = path.filename().string();
  while (std::getline(marker, line)) {
    if (line == name) return true;
  }
  return false;
}

}  // namespace

bool IsIbrOutputFile(const fs::path& path) {
  std::error_code ec;
  if (!fs::is_regular_file(fs::symlink_status(path, ec))) return false;
  if (ListedInFolderMarker(path)) return true;
  if (path.filename() == kOutputMarker) {
    // The marker itself: ibr's when it reads as one (`ibr report` adds its
    // summary to the list of an earlier report's marker).
    std::ifstream in(path);
    std::string first;
    return std::getline(in, first) && first.rfind("ibr output:", 0) == 0;
  }
  const std::string ext = Lower(path.extension().string());
  if (ext == ".ply") return TextHeaderHasMark(path, "comment", "end_header", 200);
  if (ext == ".obj" || ext == ".mtl") return TextHeaderHasMark(path, "#", nullptr, 4);
  if (ext == ".nrrd" || ext == ".nhdr") return TextHeaderHasMark(path, "#", nullptr, 8);
  // QVis: the header's `Software` line; its raw data is ibr's when the header
  // of the same name beside it is and names it.
  if (ext == ".dat") return TextHeaderHasMark(path, "Software:", nullptr, 16);
  if (ext == ".raw") {
    fs::path dat = path;
    dat.replace_extension(".dat");
    std::ifstream in(dat);
    std::string line;
    bool names_it = false;
    for (int n = 0; n < 16 && std::getline(in, line); ++n) {
      names_it = names_it || (line.rfind("ObjectFileName:", 0) == 0 &&
                              line.find(path.filename().string()) != std::string::npos);
    }
    return names_it && TextHeaderHasMark(dat, "Software:", nullptr, 16);
  }
  if (ext == ".png" || ext == ".exr" || ext == ".tif" || ext == ".tiff" || ext == ".jpg" ||
      ext == ".jpeg") {
    // The image writers' `Software` attribute (core/image_io.cc, the plots'
    // PNG text chunk in bench/report.cc), read through OpenImageIO.
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) {
      (void)OIIO::geterror();
      return false;
    }
    const std::string software = in->spec().get_string_attribute("Software");
    in->close();
    return software.find(kFileMark) != std::string::npos;
  }
  return false;
}

void SetOverwriteFiles(bool overwrite) { g_overwrite_files.store(overwrite); }

void CheckReplaceableFile(std::string_view where, const fs::path& path, bool announce) {
  std::error_code ec;
  const fs::file_status status = fs::symlink_status(path, ec);
  if (ec || !fs::exists(status)) return;
  if (fs::is_symlink(status)) {
    ThrowFileError(where, path,
                   "is a symbolic link; ibr does not write through links: give "
                   "another name");
  }
  if (fs::is_directory(status)) ThrowFileError(where, path, "is a folder; give a file name");
  if (!fs::is_regular_file(status)) ThrowFileError(where, path, "exists and is not a file");
  if (IsIbrOutputFile(path)) {
    if (announce) spdlog::info("replacing '{}', an earlier ibr output", path.string());
    return;
  }
  if (g_overwrite_files.load()) {
    if (announce) spdlog::info("replacing '{}' (--overwrite)", path.string());
    return;
  }
  ThrowFileError(where, path,
                 "exists and ibr did not write it; ibr never replaces a file it did not write: "
                 "choose a new name, or pass --overwrite to replace it");
}

void SetOutputDescription(std::string description) {
  std::lock_guard lock(g_mutex);
  std::replace(description.begin(), description.end(), '\n', ' ');
  g_description = std::move(description);
}

void NoteInputPath(const fs::path& path) {
  if (path.empty()) return;
  std::lock_guard lock(g_mutex);
  g_inputs.push_back(Canonical(path));
}

void ClearInputPaths() {
  std::lock_guard lock(g_mutex);
  g_inputs.clear();
}

void CheckNotAnInput(std::string_view where, const fs::path& output) {
  const fs::path out = Canonical(output);
  std::vector<fs::path> inputs;
  {
    std::lock_guard lock(g_mutex);
    inputs = g_inputs;
  }
  for (const fs::path& in : inputs) {
    if (Equivalent(out, in) || out == in) {
      ThrowFileError(where, output,
                     "is also an input of this command; an output never replaces its input");
    }
    if (AtOrInside(out.parent_path(), in)) {
      ThrowFileError(where, output, "is inside the input '{}'; write outputs outside their inputs",
                     in.string());
    }
    if (AtOrInside(in, out)) {
      ThrowFileError(where, output, "holds the input '{}'; an output never replaces its input",
                     in.string());
    }
  }
}

void CheckReplaceableOutput(std::string_view where, const fs::path& dir) {
  std::error_code ec;
  const fs::file_status link_status = fs::symlink_status(dir, ec);
  if (ec || !fs::exists(link_status)) return;
  if (fs::is_symlink(link_status)) {
    ThrowFileError(where, dir, "is a symbolic link; give the folder itself");
  }
  if (!fs::is_directory(link_status)) ThrowFileError(where, dir, "exists and is not a folder");
  if (fs::is_empty(dir, ec)) return;
  constexpr const char* kAdvice = "ibr only replaces its own outputs: choose a new or empty folder";
  std::ifstream marker(dir / kOutputMarker);
  std::string line;
  if (!marker || !std::getline(marker, line) || line.rfind("ibr output:", 0) != 0) {
    ThrowFileError(where, dir, "is not empty and is not an earlier ibr output (no {}); {}",
                   kOutputMarker, kAdvice);
  }
  std::set<std::string> listed;
  while (std::getline(marker, line)) listed.insert(line);
  for (const std::string& file : FilesUnder(dir)) {
    if (file != kOutputMarker && !listed.count(file)) {
      ThrowFileError(where, dir, "holds '{}', which ibr did not write; {}", file, kAdvice);
    }
  }
}

void RemoveStaleStaging(const fs::path& path) {
  const fs::path parent = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  const std::string target = path.filename().string();
  std::error_code ec;
  std::vector<fs::path> stale;
  for (fs::directory_iterator it(parent, ec), end; !ec && it != end; it.increment(ec)) {
    const long pid = StagingPid(it->path().filename().string(), target);
    if (pid > 0 && pid != ::getpid() && !ProcessAlive(pid)) stale.push_back(it->path());
  }
  for (const fs::path& p : stale) fs::remove_all(p, ec);
}

void InstallCleanupSignalHandlers() {
  g_main_thread = pthread_self();
  g_main_thread_known.store(true, std::memory_order_release);
  struct sigaction action = {};
  action.sa_handler = CleanupOnSignal;
  sigemptyset(&action.sa_mask);
  for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGABRT}) ::sigaction(sig, &action, nullptr);
}

void AtomicWrite(const fs::path& path, const std::function<void(const fs::path&)>& write,
                 ExistingFile existing) {
  const fs::path parent = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  if (!fs::is_directory(parent)) {
    ThrowFileError("output", path, "its folder '{}' does not exist", parent.string());
  }
  CheckNotAnInput("output", path);
  // Inside a staging folder nothing stale can be left (it is itself removed),
  // and nothing of the user's exists.
  if (!IsStagingPath(parent)) {
    RemoveStaleStaging(path);
    if (existing == ExistingFile::kIbrOutputOnly) CheckReplaceableFile("output", path, true);
  }
  const fs::path tmp = TemporarySibling(path);
  const int slot = RegisterCleanup(tmp);
  try {
    write(tmp);
  } catch (...) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    ReleaseCleanup(slot);
    throw;
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) fs::remove(tmp, ec);
  ReleaseCleanup(slot);
  if (ec) ThrowFileError("AtomicWrite", path, "cannot rename temporary file into place");
}

void AtomicWriteStream(const fs::path& path, const std::function<void(std::ostream&)>& write,
                       ExistingFile existing) {
  AtomicWrite(
      path,
      [&](const fs::path& tmp) {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) ThrowFileError("AtomicWriteStream", path, "cannot open for writing");
        write(out);
        out.flush();
        if (!out) ThrowFileError("AtomicWriteStream", path, "write failed");
      },
      existing);
}

StagedDirectory::StagedDirectory(fs::path final_path, bool overwrite)
    : final_path_(std::move(final_path)) {
  constexpr const char* kWhere = "output";
  if (final_path_.filename().empty()) final_path_ = final_path_.parent_path();
  if (final_path_.empty()) ThrowInputError(kWhere, "empty output path");
  CheckNotAnInput(kWhere, final_path_);
  CheckReplaceableOutput(kWhere, final_path_);
  if (!overwrite && fs::is_directory(final_path_) && !fs::is_empty(final_path_)) {
    ThrowFileError(kWhere, final_path_, "exists and is not empty");
  }
  const fs::path parent =
      final_path_.parent_path().empty() ? fs::path(".") : final_path_.parent_path();
  std::error_code ec;
  fs::create_directories(parent, ec);
  if (ec) ThrowFileError(kWhere, parent, "cannot create folder: {}", ec.message());
  RemoveStaleStaging(final_path_);
  staging_path_ = TemporarySibling(final_path_);
  cleanup_slot_ = RegisterCleanup(staging_path_);
  fs::create_directory(staging_path_, ec);
  if (ec) {
    ReleaseCleanup(cleanup_slot_);
    ThrowFileError(kWhere, staging_path_, "cannot create: {}", ec.message());
  }
}

StagedDirectory::~StagedDirectory() {
  if (!committed_) {
    std::error_code ignored;
    fs::remove_all(staging_path_, ignored);
  }
  ReleaseCleanup(cleanup_slot_);
}

void StagedDirectory::Commit() {
  IBR_CHECK(!committed_);
  constexpr const char* kWhere = "output";
  // The folder may have changed since the constructor looked at it.
  CheckReplaceableOutput(kWhere, final_path_);
  std::string description;
  {
    std::lock_guard lock(g_mutex);
    description = g_description;
  }
  const std::vector<std::string> files = FilesUnder(staging_path_);
  AtomicWriteStream(staging_path_ / kOutputMarker, [&](std::ostream& out) {
    out << "ibr output: " << description << '\n';
    for (const std::string& f : files) out << f << '\n';
  });
  std::error_code ec;
  if (fs::exists(fs::symlink_status(final_path_, ec)) && !fs::is_empty(final_path_, ec)) {
    // An earlier output (of another mesh, say) is replaced: said, with the
    // command that wrote it.
    std::ifstream marker(final_path_ / kOutputMarker);
    std::string first;
    std::getline(marker, first);
    spdlog::info("replacing '{}', an earlier ibr output ({})", final_path_.string(),
                 first.rfind("ibr output: ", 0) == 0 ? first.substr(12) : first);
  }
  if (fs::exists(fs::symlink_status(final_path_, ec))) {
    // Swap the new folder and the old one in one step, then remove the old
    // one, now under the (still registered) staging name.
    if (::renameat2(AT_FDCWD, staging_path_.c_str(), AT_FDCWD, final_path_.c_str(),
                    RENAME_EXCHANGE) != 0) {
      const int error = errno;
      if (error != EINVAL && error != ENOSYS) {
        ThrowFileError(kWhere, final_path_, "cannot replace: {}", std::strerror(error));
      }
      // No exchange on this file system: two renames.
      const fs::path old = TemporarySibling(final_path_);
      fs::rename(final_path_, old, ec);
      if (ec) ThrowFileError(kWhere, final_path_, "cannot replace: {}", ec.message());
      fs::rename(staging_path_, final_path_, ec);
      if (ec) {
        fs::rename(old, final_path_, ec);
        ThrowFileError(kWhere, final_path_, "cannot move into place");
      }
      fs::remove_all(old, ec);
    }
    committed_ = true;
    fs::remove_all(staging_path_, ec);
  } else {
    fs::rename(staging_path_, final_path_, ec);
    if (ec) ThrowFileError(kWhere, final_path_, "cannot move into place: {}", ec.message());
    committed_ = true;
  }
  ReleaseCleanup(cleanup_slot_);
  cleanup_slot_ = -1;
}

}  // namespace core
