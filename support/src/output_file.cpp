#include <crep/support/output_file.h>

#include <crep/core/error.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <string>
#include <sys/stat.h>
#include <unistd.h>

namespace crep {

namespace fs = std::filesystem;

namespace {

/// Longest symbolic link chain followed (Linux's own limit for path resolution).
constexpr int kMaxLinks = 40;

std::string quoted(const fs::path& p) {
  return "'" + p.string() + "'";
}

[[noreturn]] void fail(const fs::path& path, const std::string& why) {
  throw IoError("crep: cannot write " + quoted(path) + ": " + why);
}

/// "a directory", "a character device", ... for a file that is not a regular file.
const char* kindOf(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

/// Refuses (rule 2) when `status` describes an existing file that is not a regular file.
void requireRegular(const fs::path& path, const fs::path& target, const struct stat& status) {
  if (S_ISREG(status.st_mode)) return;
  const std::string where = target == path ? "it" : "its target " + quoted(target);
  fail(path, where + " is " + kindOf(status.st_mode) +
                 ", not a regular file; outputs only create or replace regular files");
}

/// The end of the symbolic link chain starting at `path` (which may not exist).
fs::path followLinks(const fs::path& path) {
  fs::path p = path;
  for (int i = 0; i <= kMaxLinks; ++i) {
    struct stat status {};
    if (::lstat(p.c_str(), &status) != 0 || !S_ISLNK(status.st_mode)) return p;
    std::error_code ec;
    const fs::path link = fs::read_symlink(p, ec);
    if (ec) fail(path, "cannot read the symbolic link " + quoted(p) + ": " + ec.message());
    p = link.is_absolute() ? link : p.parent_path() / link;
  }
  fail(path, "more than " + std::to_string(kMaxLinks) + " symbolic links to follow");
}

/// A name for a temporary next to `target` that no other writer of this process picks at the same time.
fs::path temporaryName(const fs::path& target, int attempt) {
  static std::atomic<unsigned> counter{0};
  const auto now =
      static_cast<unsigned long long>(std::chrono::steady_clock::now().time_since_epoch().count());
  unsigned long long v = now ^ (static_cast<unsigned long long>(::getpid()) << 32) ^
                         (static_cast<unsigned long long>(counter.fetch_add(1)) * 0x9E3779B97F4A7C15ull) ^
                         static_cast<unsigned long long>(attempt);
  std::string suffix = ".crep-";
  static const char kDigits[] = "abcdefghijklmnopqrstuvwxyz0123456789";
  for (int i = 0; i < 6; ++i) {
    suffix += kDigits[v % 36];
    v /= 36;
  }
  suffix += ".partial";
  std::string name = target.filename().string();
  constexpr std::size_t kMaxName = 255; // NAME_MAX of the common file systems
  if (name.size() + suffix.size() > kMaxName) name.resize(kMaxName - suffix.size());
  return target.parent_path() / (name + suffix);
}

} // namespace

fs::path resolveOutputTarget(const fs::path& path) {
  if (path.empty()) fail(path, "the path is empty");
  const fs::path target = followLinks(path);
  struct stat status {};
  if (::stat(path.c_str(), &status) == 0) {
    requireRegular(path, target, status);
  } else if (errno != ENOENT) {
    fail(path, std::strerror(errno));
  }
  if (!target.has_filename()) fail(path, "it names a directory, not a file");
  const fs::path parent = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  struct stat dir {};
  if (::stat(parent.c_str(), &dir) != 0)
    fail(path, "directory " + quoted(parent) +
                   (errno == ENOENT ? " does not exist" : ": " + std::string(std::strerror(errno))));
  if (!S_ISDIR(dir.st_mode)) fail(path, quoted(parent) + " is not a directory");
  return target;
}

PendingOutput::PendingOutput(const fs::path& path) : path_(path), target_(resolveOutputTarget(path)) {
  struct stat existing {};
  const bool exists = ::stat(target_.c_str(), &existing) == 0;
  for (int attempt = 0; attempt < 100; ++attempt) {
    const fs::path name = temporaryName(target_, attempt);
    const int fd = ::open(name.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0666);
    if (fd < 0) {
      if (errno == EEXIST) continue;
      const std::string why = std::strerror(errno);
      fail(path, "cannot create a file in " + quoted(name.parent_path().empty() ? "." : name.parent_path()) +
                     ": " + why);
    }
    // Keep a replaced file's permission bits (a new file has the umask's).
    const bool modeOk = !exists || ::fchmod(fd, existing.st_mode & 07777) == 0;
    const int chmodErrno = errno;
    ::close(fd);
    temporary_ = name;
    if (!modeOk) {
      discard();
      fail(path, "cannot set the permissions of " + quoted(name) + ": " + std::strerror(chmodErrno));
    }
    return;
  }
  fail(path, "cannot find an unused temporary name next to " + quoted(target_));
}

PendingOutput::PendingOutput(PendingOutput&& other) noexcept
    : path_(std::move(other.path_)), target_(std::move(other.target_)),
      temporary_(std::move(other.temporary_)) {
  other.temporary_.clear();
}

PendingOutput& PendingOutput::operator=(PendingOutput&& other) noexcept {
  if (this != &other) {
    discard();
    path_ = std::move(other.path_);
    target_ = std::move(other.target_);
    temporary_ = std::move(other.temporary_);
    other.temporary_.clear();
  }
  return *this;
}

PendingOutput::~PendingOutput() {
  discard();
}

void PendingOutput::commit() {
  if (temporary_.empty()) fail(path_, "nothing to commit (no temporary file)");
  // Rule 2 again: the target may have changed since the temporary was created.
  struct stat status {};
  if (::stat(target_.c_str(), &status) == 0 && !S_ISREG(status.st_mode)) {
    discard();
    requireRegular(path_, target_, status);
  }
  if (::rename(temporary_.c_str(), target_.c_str()) != 0) {
    const std::string why = std::strerror(errno);
    discard();
    fail(path_, "cannot rename the temporary file over " + quoted(target_) + ": " + why);
  }
  temporary_.clear();
}

void PendingOutput::discard() noexcept {
  if (temporary_.empty()) return;
  ::unlink(temporary_.c_str());
  temporary_.clear();
}

void writeOutputFile(const fs::path& path, const std::function<void(const fs::path& temporary)>& write) {
  PendingOutput output(path);
  write(output.temporary()); // on an exception the destructor removes the temporary
  output.commit();
}

void writeTextFile(const fs::path& path, std::string_view text) {
  writeOutputFile(path, [&](const fs::path& temporary) {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) fail(path, "cannot open " + quoted(temporary) + " for writing");
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.close();
    if (!out) fail(path, "write failed");
  });
}

} // namespace crep
