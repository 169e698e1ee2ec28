#include "leglab/app/output.h"

#include <fcntl.h>
#include <pthread.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <algorithm>
#include <cassert>
#include <cerrno>
#include <charconv>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <system_error>
#include <thread>
#include <utility>
#include <variant>

#include "leglab/app/input_error.h"
#include "leglab/app/progress.h"
#include "leglab/core/format.h"

namespace leglab {

namespace fs = std::filesystem;

namespace {

// The staging folders that exist now, for the interrupt watcher; the mutex also makes a
// commit and an interruption's clean-up exclude each other. Never destroyed: the watcher
// thread may use it while the process exits.
struct StagingRegistry {
  std::mutex mutex;
  std::vector<fs::path> folders;
  // The lock files this process holds: removed by the clean-up too.
  std::vector<fs::path> lock_files;
};

StagingRegistry& Registry() {
  static auto* registry = new StagingRegistry;
  return *registry;
}

[[noreturn]] void BadOut(const fs::path& out, const std::string& what) {
  throw InputError("--out '" + out.string() + "' " + what);
}

bool Owned(const std::vector<std::string>& prefixes, const std::string& name) {
  for (const std::string& prefix : prefixes) {
    if (name.rfind(prefix, 0) == 0) return true;
  }
  return false;
}

// Removes `folder` even while a worker thread may still be creating files in it (an
// interruption mid-write): a few passes, each removing what the last one missed.
void RemoveStaging(const fs::path& folder) {
  std::error_code ec;
  for (int pass = 0; pass < 100 && fs::exists(folder, ec); ++pass) fs::remove_all(folder, ec);
}

// What TryLock found.
enum class LockResult { kTaken, kHeld, kUnsupported };

// Takes an exclusive flock on the lock file `path` (created if missing) without waiting and
// writes this process's id into it. kHeld (with the holder's id in `holder`, 0 if unknown)
// when another open file holds it; kUnsupported when the file system has no flock (the run
// goes on unlocked). Throws OutputError if the file cannot be created.
LockResult TryLock(const fs::path& path, int& fd, long& holder) {
  for (;;) {
    fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) throw OutputError("cannot create the lock file " + path.string());
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int error = errno;
      if (error == EWOULDBLOCK) {
        char text[24] = {};
        const ssize_t n = ::pread(fd, text, sizeof text - 1, 0);
        holder = n > 0 ? std::strtol(text, nullptr, 10) : 0;
        ::close(fd);
        fd = -1;
        return LockResult::kHeld;
      }
      // No flock here (e.g. an NFS mount without locks): nobody can hold this file.
      ::unlink(path.c_str());
      ::close(fd);
      fd = -1;
      return LockResult::kUnsupported;
    }
    // A holder removes the file before it lets go, so a lock on a file that is no longer at
    // `path` excludes nobody: open the one there now and try again.
    struct stat held {};
    struct stat named {};
    if (::fstat(fd, &held) == 0 && ::stat(path.c_str(), &named) == 0 &&
        held.st_dev == named.st_dev && held.st_ino == named.st_ino) {
      const std::string pid = std::to_string(::getpid()) + "\n";
      if (::ftruncate(fd, 0) != 0 ||
          ::pwrite(fd, pid.data(), pid.size(), 0) != static_cast<ssize_t>(pid.size())) {
        // The id is only for the refusal's message: a lock without it still excludes.
      }
      return LockResult::kTaken;
    }
    ::close(fd);
  }
}

// Removes the lock file, then lets go of it (in this order: see TryLock). The registry's mutex
// must be held.
void ReleaseLock(fs::path& path, int& fd) {
  if (fd < 0) return;
  ::unlink(path.c_str());
  ::close(fd);
  fd = -1;
  std::vector<fs::path>& files = Registry().lock_files;
  files.erase(std::remove(files.begin(), files.end(), path), files.end());
  path.clear();
}

// The lock file of `final_dir` (absolute, normalised) when its parent does not exist yet: in
// the temporary folder `where`, named by a hash (FNV-1a, the same in every build) of the path.
fs::path TemporaryLockPath(const fs::path& where, const fs::path& final_dir) {
  std::uint64_t hash = 14695981039346656037ULL;
  for (const char c : final_dir.string()) {
    hash = (hash ^ static_cast<unsigned char>(c)) * 1099511628211ULL;
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(hash));
  return where / (".leglab-out-" + std::string(hex) + ".lock");
}

// The lock file beside `final_dir`.
fs::path LockPathBeside(const fs::path& final_dir) {
  std::string name = final_dir.filename().string();
  name.insert(0, 1, '.');  // not "." + name: GCC 12 warns (-Wrestrict) about that
  return final_dir.parent_path() / (name + ".lock");
}

// The refusal of a second run.
std::string HeldMessage(long holder) {
  return "is being written by another run" +
         (holder > 0 ? " (process " + std::to_string(holder) + ")" : std::string()) +
         ": wait for it to finish or choose another folder";
}

// Exchanges the two paths (both exist) in one step; false if the file system cannot.
bool ExchangePaths(const fs::path& a, const fs::path& b) {
  return ::renameat2(AT_FDCWD, a.c_str(), AT_FDCWD, b.c_str(), RENAME_EXCHANGE) == 0;
}

// Whether folder `path` is where a file system is mounted (its root): such a folder cannot be
// renamed or moved, so a commit that swaps folders would leave it behind. statx says so
// directly where the kernel reports STATX_ATTR_MOUNT_ROOT; elsewhere a device other than the
// parent's gives it away (all but bind mounts within one file system).
bool IsMountPoint(const fs::path& path) {
  struct statx here {};
  if (::statx(AT_FDCWD, path.c_str(), AT_SYMLINK_NOFOLLOW, STATX_BASIC_STATS, &here) != 0) {
    return false;
  }
  if ((here.stx_attributes_mask & STATX_ATTR_MOUNT_ROOT) != 0) {
    return (here.stx_attributes & STATX_ATTR_MOUNT_ROOT) != 0;
  }
  struct stat parent {};
  if (::stat((path / "..").c_str(), &parent) != 0) return false;
  return makedev(here.stx_dev_major, here.stx_dev_minor) != parent.st_dev;
}

// Whether `final_dir` or a folder in it is a mount point (IsMountPoint).
bool HoldsMountPoint(const fs::path& final_dir) {
  if (IsMountPoint(final_dir)) return true;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(final_dir, ec)) {
    if (entry.is_directory(ec) && !entry.is_symlink(ec) && IsMountPoint(entry.path())) {
      return true;
    }
  }
  return false;
}

}  // namespace

fs::path CheckOutFolder(const fs::path& out, const std::vector<std::string>& owned_prefixes) {
  if (out.empty()) throw InputError("--out must name a folder, got an empty path");
  std::error_code ec;
  fs::path folder = out;
  // A link to a folder: the folder is what gets replaced, the link stays. A link that leads
  // nowhere (dangling, or a loop) is refused now, not at the commit after the whole run.
  if (fs::is_symlink(folder, ec)) {
    const fs::path target = fs::read_symlink(folder, ec);
    folder = fs::canonical(folder, ec);
    if (ec == std::errc::too_many_symbolic_link_levels) BadOut(out, "is a loop of symbolic links");
    if (ec) {
      BadOut(out, "is a symbolic link to '" + target.string() + "', which cannot be followed (" +
                      ec.message() + ")");
    }
  }
  folder = fs::absolute(folder, ec).lexically_normal();
  if (ec) BadOut(out, "cannot be resolved: " + ec.message());
  // A path the file system cannot look up (a loop of links on the way) is refused likewise.
  (void)fs::status(folder, ec);
  // (A file on the way is found below and named.)
  if (ec && ec != std::errc::no_such_file_or_directory && ec != std::errc::not_a_directory) {
    BadOut(out, "cannot be looked up: " + ec.message());
  }
  if (!folder.has_filename()) folder = folder.parent_path();
  if (folder == folder.root_path()) BadOut(out, "is the root folder");
  if (fs::exists(folder, ec)) {
    if (!fs::is_directory(folder, ec)) BadOut(out, "exists and is not a folder");
    for (const auto& entry : fs::directory_iterator(folder, ec)) {
      const std::string name = entry.path().filename().string();
      if (Owned(owned_prefixes, name) && !entry.is_regular_file()) {
        BadOut(out, "holds '" + name + "', which is not a file, where this program writes one");
      }
    }
    if (ec) BadOut(out, "cannot be read: " + ec.message());
    // Its files are replaced in it (and, for a mount point, written in it): a read-only folder
    // or file system is refused before the run, not at its commit.
    if (::access(folder.c_str(), W_OK | X_OK) != 0) {
      BadOut(out, std::string("cannot be written: ") + std::strerror(errno));
    }
  }
  // The nearest folder that exists is where the first new folder will be created.
  fs::path existing = folder.parent_path();
  while (!fs::exists(existing, ec) && existing != existing.root_path()) {
    existing = existing.parent_path();
  }
  if (!fs::is_directory(existing, ec))
    BadOut(out, "lies under '" + existing.string() + "', a file");
  if (::access(existing.c_str(), W_OK | X_OK) != 0) {
    BadOut(out, "cannot be written: no write permission in '" + existing.string() + "'");
  }
  return folder;
}

OutputDir::OutputDir(fs::path final_dir, std::vector<std::string> owned_prefixes)
    : final_dir_(std::move(final_dir)), owned_prefixes_(std::move(owned_prefixes)) {
  const fs::path given = final_dir_;
  final_dir_ = CheckOutFolder(given, owned_prefixes_);
  std::error_code ec;
  // Beside --out a commit is a rename; with no parent yet, stage where creating leaves no trace.
  const fs::path parent = final_dir_.parent_path();
  fs::path where = parent;
  if (!fs::is_directory(parent, ec)) {
    where = fs::temp_directory_path(ec);
    if (ec || !fs::is_directory(where, ec)) {
      const char* tmpdir = std::getenv("TMPDIR");
      BadOut(given, "has no parent folder yet, and the temporary folder to stage in " +
                        (tmpdir != nullptr ? "(TMPDIR='" + std::string(tmpdir) + "') " : "") +
                        "does not exist");
    }
  }
  const std::lock_guard<std::mutex> lock(Registry().mutex);
  // The lock before the staging folder: a second run is refused before it does anything.
  const fs::path lock_path =
      where == parent ? LockPathBeside(final_dir_) : TemporaryLockPath(where, final_dir_);
  long holder = 0;
  try {
    const LockResult locked = TryLock(lock_path, lock_fd_, holder);
    if (locked == LockResult::kHeld) BadOut(given, HeldMessage(holder));
    if (locked == LockResult::kTaken) {
      lock_path_ = lock_path;
      Registry().lock_files.push_back(lock_path_);
    }
  } catch (const OutputError& e) {
    BadOut(given, std::string("cannot be written: ") + e.what());
  }
  for (int attempt = 0;; ++attempt) {
    std::string name = final_dir_.filename().string();
    name.insert(0, 1, '.');
    name += ".staging-" + std::to_string(::getpid()) + "-" + std::to_string(attempt);
    staging_ = where / name;
    if (fs::create_directory(staging_, ec)) break;
    if (ec || attempt > 100) {
      ReleaseLock(lock_path_, lock_fd_);
      BadOut(given, "cannot be written: no staging folder in '" + where.string() +
                        "': " + (ec ? ec.message() : "too many attempts"));
    }
  }
  Registry().folders.push_back(staging_);
}

OutputDir::~OutputDir() {
  const std::lock_guard<std::mutex> lock(Registry().mutex);
  std::vector<fs::path>& folders = Registry().folders;
  folders.erase(std::remove(folders.begin(), folders.end(), staging_), folders.end());
  RemoveStaging(staging_);
  ReleaseLock(lock_path_, lock_fd_);
}

fs::path OutputDir::Path(const std::string& name) const {
  SetProgressPhase("writing " + name);
  return staging_ / name;
}

void OutputDir::Commit() {
  assert(!committed_);
  // An interruption waits for the commit, and a commit for an interruption's clean-up.
  const std::lock_guard<std::mutex> lock(Registry().mutex);
  std::error_code ec;
  auto fail = [&](const std::string& what) {
    throw OutputError("cannot commit into " + final_dir_.string() + ": " + what);
  };
  const fs::path parent = final_dir_.parent_path();
  if (staging_.parent_path() != parent) {
    // Staged in the temporary folder: create the parents, then stage again beside --out (a
    // copy, invisible until the rename), so that the commit is still one rename.
    fs::create_directories(parent, ec);
    if (ec) fail("cannot create " + parent.string() + ": " + ec.message());
    // A run that started once the parent existed locks beside --out: take that lock too.
    if (lock_fd_ >= 0) {
      int fd = -1;
      long holder = 0;
      const fs::path lock_path = LockPathBeside(final_dir_);
      const LockResult locked = TryLock(lock_path, fd, holder);
      if (locked == LockResult::kHeld) fail(HeldMessage(holder));
      ReleaseLock(lock_path_, lock_fd_);
      if (locked == LockResult::kTaken) {
        lock_path_ = lock_path;
        lock_fd_ = fd;
        Registry().lock_files.push_back(lock_path_);
      }
    }
    const fs::path beside = parent / staging_.filename();
    fs::rename(staging_, beside, ec);
    if (ec) {
      fs::copy(staging_, beside, fs::copy_options::recursive, ec);
      if (ec) fail("cannot stage in " + parent.string() + ": " + ec.message());
      RemoveStaging(staging_);
    }
    std::vector<fs::path>& folders = Registry().folders;
    std::replace(folders.begin(), folders.end(), staging_, beside);
    staging_ = beside;
  }
  if (!fs::exists(final_dir_, ec)) {
    fs::rename(staging_, final_dir_, ec);
    if (ec) fail(ec.message());
    committed_ = true;
    ReleaseLock(lock_path_, lock_fd_);
    FinishProgress();
    return;
  }
  if (HoldsMountPoint(final_dir_)) {
    CommitFileByFile();
    return;
  }
  // --out exists: the staging folder takes over everything it holds but the files this run
  // wrote anew, by full name (files as hard links, links as links; folders are moved once the
  // swap is done). A file the program did not write this time, even one named like its output
  // (the user's notes, a trace of a mode not run now), is kept.
  std::vector<fs::path> folders_to_move;
  for (const auto& entry : fs::directory_iterator(final_dir_)) {
    const fs::path name = entry.path().filename();
    if (fs::is_regular_file(staging_ / name, ec) && !entry.is_directory()) continue;
    const fs::path target = staging_ / name;
    if (entry.is_symlink()) {
      fs::copy_symlink(entry.path(), target, ec);
    } else if (entry.is_directory()) {
      folders_to_move.push_back(name);
      continue;
    } else {
      fs::create_hard_link(entry.path(), target, ec);
      if (ec) fs::copy_file(entry.path(), target, ec);
    }
    if (ec) fail("cannot keep " + entry.path().string() + ": " + ec.message());
  }
  if (!ExchangePaths(staging_, final_dir_)) {
    // No RENAME_EXCHANGE here: the old folder aside, the new one in, a moment without either.
    fs::rename(final_dir_, staging_.string() + "-old", ec);
    if (ec) fail(ec.message());
    fs::rename(staging_, final_dir_, ec);
    if (ec) {
      fs::rename(staging_.string() + "-old", final_dir_);
      fail(ec.message());
    }
    RemoveStaging(staging_);
    fs::rename(staging_.string() + "-old", staging_, ec);
  }
  // staging_ now holds the previous results.
  committed_ = true;
  FinishProgress();
  // Released once the folders are back (the destructor releases it if they cannot be).
  for (const fs::path& name : folders_to_move) {
    fs::rename(staging_ / name, final_dir_ / name, ec);
    if (ec) {
      // Keep the previous results rather than lose a folder of them.
      std::vector<fs::path>& folders = Registry().folders;
      folders.erase(std::remove(folders.begin(), folders.end(), staging_), folders.end());
      const fs::path kept = staging_;
      staging_.clear();  // not removed by the destructor
      throw OutputError("committed into " + final_dir_.string() + ", but could not move " +
                        name.string() + " back into it (" + ec.message() + "): it is in " +
                        kept.string());
    }
  }
  ReleaseLock(lock_path_, lock_fd_);
}

void OutputDir::CommitFileByFile() {
  std::error_code ec;
  auto fail = [&](const std::string& what) {
    throw OutputError("cannot commit into " + final_dir_.string() + ": " + what);
  };
  // A mount point cannot change folders: the staged files go into --out one by one instead
  // (each whole, by rename), and nothing of --out is moved. With --out itself mounted, the
  // staging folder beside it is on another file system: each file is copied in under a hidden
  // name first and renamed over its target.
  for (const auto& entry : fs::directory_iterator(staging_)) {
    const std::string name = entry.path().filename().string();
    fs::rename(entry.path(), final_dir_ / name, ec);
    if (ec == std::errc::cross_device_link) {
      const fs::path copy = final_dir_ / ("." + name + ".leglab-" + std::to_string(::getpid()));
      fs::copy_file(entry.path(), copy, fs::copy_options::overwrite_existing, ec);
      if (!ec) fs::rename(copy, final_dir_ / name, ec);
      if (ec) {
        std::error_code ignored;
        fs::remove(copy, ignored);
      }
    }
    if (ec) fail("cannot move " + name + " in: " + ec.message());
  }
  committed_ = true;
  RemoveStaging(staging_);
  ReleaseLock(lock_path_, lock_fd_);
  FinishProgress();
}

void InstallInterruptCleanup(const std::string& program) {
  sigset_t signals;
  sigemptyset(&signals);
  for (const int s : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&signals, s);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  std::thread([signals, program] {
    int signal = 0;
    while (sigwait(&signals, &signal) != 0) {
    }
    // Waits for a commit in progress; holds the lock until the process is gone, so that no
    // commit starts after the clean-up.
    Registry().mutex.lock();
    for (const fs::path& folder : Registry().folders) RemoveStaging(folder);
    // Still held: the locks go with the process.
    for (const fs::path& file : Registry().lock_files) ::unlink(file.c_str());
    std::fprintf(stderr, "%s: interrupted by signal %d\n", program.c_str(), signal);
    std::fflush(stderr);
    std::_Exit(128 + signal);
  }).detach();
}

void WriteTextFile(const fs::path& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  out.close();
  if (!out) throw OutputError("cannot write " + path.string());
}

std::string FormatDouble(double value) { return FormatNumber(value); }

CsvWriter::CsvWriter(const fs::path& path, const std::vector<std::string>& columns, bool append)
    : path_(path), columns_(columns.size()) {
  std::error_code ec;
  const bool header = !append || !fs::exists(path, ec);
  out_.open(path, append ? std::ios::app : std::ios::trunc);
  if (!out_) throw OutputError("cannot write " + path.string());
  if (!header) return;
  for (const std::string& c : columns) CsvWriter::Cell(c);
  CsvWriter::EndRow();
}

CsvWriter::~CsvWriter() { Flush(); }

void CsvWriter::Flush() {
  if (pending_.empty()) return;
  out_.write(pending_.data(), static_cast<std::streamsize>(pending_.size()));
  pending_.clear();
}

void CsvWriter::Separator() {
  if (in_row_++ > 0) pending_ += ',';
}

CsvWriter& CsvWriter::Cell(double value) {
  Separator();
  AppendNumber(pending_, value);
  return *this;
}

CsvWriter& CsvWriter::Cell(long value) {
  Separator();
  char buffer[24];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  pending_.append(buffer, result.ptr);
  return *this;
}

CsvWriter& CsvWriter::Cell(const std::string& text) {
  Separator();
  pending_ += text;
  return *this;
}

void CsvWriter::EndRow() {
  assert(in_row_ == columns_);
  pending_ += '\n';
  in_row_ = 0;
  if (pending_.size() >= 1 << 16) Flush();
}

void CsvWriter::Close() {
  Flush();
  out_.close();
  if (!out_) throw OutputError("cannot write " + path_.string());
}

ColumnTable::ColumnTable(std::vector<std::string> column_names)
    : names(std::move(column_names)), columns(names.size()) {}

template <typename T>
ColumnTable& ColumnTable::Append(T value) {
  assert(in_row_ < columns.size() && "a row has a cell per column");
  Column& column = columns[in_row_++];
  // Every column starts as an empty vector<double>: the first cell sets its type.
  if (rows_ == 0 && !std::holds_alternative<std::vector<T>>(column)) {
    column.emplace<std::vector<T>>();
  }
  assert(std::holds_alternative<std::vector<T>>(column) && "a column holds one type");
  std::get<std::vector<T>>(column).push_back(std::move(value));
  return *this;
}

ColumnTable& ColumnTable::Cell(double value) { return Append(value); }

ColumnTable& ColumnTable::Cell(long value) { return Append(value); }

ColumnTable& ColumnTable::Cell(const std::string& text) { return Append(text); }

void ColumnTable::EndRow() {
  assert(in_row_ == columns.size() && "a row has a cell per column");
  in_row_ = 0;
  ++rows_;
}

}  // namespace leglab
