// Output files: target classification, collision checks, atomic replacement and streaming.
#include "io/files/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>

#include "io/files/error.h"
#include "io/files/hash.h"

namespace penumbra {
namespace fs = std::filesystem;
namespace {

// A fixed table of temporaries in flight, readable from a signal handler without locks.
constexpr int kSlots = 16;
constexpr size_t kPathMax = 4096;
constexpr int kMaxSymlinks = 40;  // as the kernel's own limit on a path's links
char g_paths[kSlots][kPathMax];
std::atomic<bool> g_used[kSlots];

std::atomic<bool> g_ready[kSlots];  // the slot's path is complete: the handler may unlink it

int claim_slot(const std::string& path) {
  if (path.size() >= kPathMax) return -1;
  for (int i = 0; i < kSlots; ++i) {
    bool expected = false;
    if (g_used[i].compare_exchange_strong(expected, true)) {
      std::memcpy(g_paths[i], path.c_str(), path.size() + 1);
      g_ready[i].store(true, std::memory_order_release);
      return i;
    }
  }
  return -1;
}

void release_slot(int i) {
  if (i < 0) return;
  g_ready[i].store(false, std::memory_order_release);
  g_used[i].store(false);
}

std::string errno_text(int err) {
  return std::strerror(err);
}

[[noreturn]] void fail(const fs::path& path, const std::string& what, int err) {
  throw std::runtime_error(path.string() + ": " + what + ": " + errno_text(err));
}

/// The descriptor a path names directly: /dev/stdout, /dev/stderr, /dev/fd/N, /proc/self/fd/N.
int descriptor_path(const std::string& p) {
  if (p == "/dev/stdout") return STDOUT_FILENO;
  if (p == "/dev/stderr") return STDERR_FILENO;
  for (const char* prefix : {"/dev/fd/", "/proc/self/fd/"}) {
    const size_t n = std::strlen(prefix);
    if (p.size() > n && p.size() <= n + 6 && p.compare(0, n, prefix) == 0 &&
        p.find_first_not_of("0123456789", n) == std::string::npos)
      return std::stoi(p.substr(n));
  }
  return -1;
}

/// Writes all of `bytes` to `fd`, retrying short writes and EINTR. Returns 0 or the errno.
int write_all(int fd, const unsigned char* bytes, size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, bytes, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    bytes += n;
    size -= size_t(n);
  }
  return 0;
}

/// fsync()s a finished file so that a full disk or an I/O error surfaces before the rename.
void sync_file(const fs::path& path, const fs::path& shown_as) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) fail(shown_as, "cannot reopen the finished file", errno);
  const int r = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  if (r != 0 && err != EINVAL) fail(shown_as, "cannot sync to disk", err);
}

/// Copies `source` to the stream target (descriptor or opened path), hashing what it sends.
void stream_to(const OutputTarget& t, const fs::path& source, std::string* sha256) {
  const int in = ::open(source.c_str(), O_RDONLY | O_CLOEXEC);
  if (in < 0) fail(source, "cannot reopen the finished file", errno);
  const int out = t.fd >= 0 ? t.fd : ::open(t.target.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC);
  if (out < 0) {
    const int err = errno;
    ::close(in);
    fail(t.target, "cannot open for writing", err);
  }
  Sha256 hash;
  std::vector<unsigned char> buf(1 << 20);
  int err = 0;
  for (;;) {
    const ssize_t n = ::read(in, buf.data(), buf.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      err = errno;
      break;
    }
    if (n == 0) break;
    hash.update(buf.data(), size_t(n));
    if ((err = write_all(out, buf.data(), size_t(n))) != 0) break;
  }
  ::close(in);
  if (t.fd < 0 && ::close(out) != 0 && err == 0) err = errno;
  if (err != 0) fail(t.target, "write failed", err);
  if (sha256) *sha256 = hash.finish_hex();
}

}  // namespace

void remove_pending_temporaries() noexcept {
  for (int i = 0; i < kSlots; ++i)
    if (g_ready[i].load(std::memory_order_acquire)) ::unlink(g_paths[i]);
}

OutputTarget resolve_output(const fs::path& destination, const std::string& element) {
  OutputTarget t;
  const std::string given = destination.string();
  const std::string where = element.empty() ? given : element + " " + given;  // "--png out/a.png"
  if (given.empty()) throw InputError("", element, "empty output path");
  if (const int fd = descriptor_path(given); fd >= 0) {
    struct stat st {};
    if (::fstat(fd, &st) != 0)
      throw InputError("", where, "descriptor " + std::to_string(fd) + " is not open");
    t.kind = OutputKind::Stream;
    t.target = destination;
    t.fd = fd;
    t.device = st.st_dev;
    t.inode = st.st_ino;
    return t;
  }
  fs::path p = destination;
  for (int links = 0;; ++links) {
    struct stat st {};
    if (::lstat(p.c_str(), &st) != 0) {
      const int err = errno;
      if (err != ENOENT)
        throw InputError("", where, "cannot access '" + p.string() + "': " + errno_text(err));
      const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
      std::error_code ec;
      if (!fs::is_directory(dir, ec))
        throw InputError("", where, "directory '" + dir.string() + "' does not exist");
      t.target = p;
      return t;
    }
    if (S_ISLNK(st.st_mode)) {
      if (links >= kMaxSymlinks) throw InputError("", where, "too many levels of symbolic links");
      std::error_code ec;
      const fs::path link = fs::read_symlink(p, ec);
      if (ec)
        throw InputError("", where, "cannot read the symbolic link '" + p.string() + "': " + ec.message());
      p = link.is_absolute() ? link : (p.has_parent_path() ? p.parent_path() : fs::path(".")) / link;
      if (const int fd = descriptor_path(p.lexically_normal().string()); fd >= 0)
        return resolve_output(p, element);
      continue;
    }
    t.target = p;
    t.device = st.st_dev;
    t.inode = st.st_ino;
    if (S_ISREG(st.st_mode)) return t;
    if (S_ISCHR(st.st_mode) || S_ISFIFO(st.st_mode)) {
      t.kind = OutputKind::Stream;
      return t;
    }
    const char* what =
        S_ISDIR(st.st_mode) ? "a directory" : (S_ISSOCK(st.st_mode) ? "a socket" : "a block device");
    throw InputError("", where,
                     std::string("is ") + what +
                         "; an output replaces only a regular file (or streams to a "
                         "character device or FIFO)");
  }
}

void check_distinct_files(const std::vector<std::pair<std::string, fs::path>>& outputs,
                          const std::vector<std::pair<std::string, fs::path>>& inputs) {
  // Existing files are identified by device and inode, new ones by their resolved path.
  auto identity = [](const OutputTarget& t) {
    if (t.device != 0 || t.inode != 0)
      return "inode " + std::to_string(t.device) + ":" + std::to_string(t.inode);
    std::error_code ec;
    const fs::path dir = fs::weakly_canonical(t.target.has_parent_path() ? t.target.parent_path() : ".", ec);
    return "path " + (dir / t.target.filename()).string();
  };
  std::map<std::string, std::string> seen;  // identity -> "option path"
  for (const auto& [option, path] : outputs) {
    const std::string id = identity(resolve_output(path, option));
    const std::string name = option + " " + path.string();
    const auto [it, fresh] = seen.emplace(id, name);
    if (!fresh)
      throw InputError("", "",
                       it->second + " and " + name + " are the same file; every output needs its own path");
  }
  for (const auto& [option, path] : inputs) {
    struct stat st {};
    if (path.empty() || ::stat(path.c_str(), &st) != 0) continue;
    const auto it = seen.find("inode " + std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino));
    if (it != seen.end())
      throw InputError(
          "", "", it->second + " would overwrite " + option + " " + path.string() + ", which this run reads");
  }
}

void write_file_checked(const fs::path& path, const void* bytes, size_t size, const fs::path& shown_as) {
  const fs::path& name = shown_as.empty() ? path : shown_as;
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) fail(name, "cannot open for writing", errno);
  int err = write_all(fd, static_cast<const unsigned char*>(bytes), size);
  if (err == 0 && ::fsync(fd) != 0 && errno != EINVAL) err = errno;
  if (::close(fd) != 0 && err == 0) err = errno;
  if (err != 0) fail(name, "write failed", err);
}

void write_atomically(const fs::path& destination, const std::function<void(const fs::path&)>& write,
                      std::string* sha256) {
  static std::atomic<int> counter{0};
  const OutputTarget t = resolve_output(destination);
  const std::string unique = std::to_string(::getpid()) + "-" + std::to_string(counter++);
  const fs::path& final_path = t.target;
  const fs::path dir = t.kind == OutputKind::Stream
                           ? fs::temp_directory_path()
                           : (final_path.has_parent_path() ? final_path.parent_path() : fs::path("."));
  const fs::path temp =
      dir / ("." + final_path.stem().string() + ".tmp-" + unique + final_path.extension().string());
  // Registered before it exists, so a signal never leaves it behind; created by us, so that a
  // failure reports the real reason (permissions, full disk, ...).
  const int slot = claim_slot(temp.string());
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) {
    const int err = errno;
    release_slot(slot);
    fail(destination, "cannot create a temporary file in '" + dir.string() + "'", err);
  }
  ::close(fd);
  auto discard = [&] {
    ::unlink(temp.c_str());
    release_slot(slot);
  };
  try {
    write(temp);
    sync_file(temp, destination);
    if (t.kind == OutputKind::Stream) {
      stream_to(t, temp, sha256);
      discard();
      return;
    }
    if (sha256) {
      try {
        *sha256 = sha256_file(temp);
      } catch (const InputError& e) {  // our own temporary: an I/O failure, not bad input
        throw std::runtime_error(e.what());
      }
    }
    struct stat old {};
    if ((t.device != 0 || t.inode != 0) && ::stat(final_path.c_str(), &old) == 0)
      ::chmod(temp.c_str(), old.st_mode & 07777);
  } catch (...) {
    discard();
    throw;
  }
  if (::rename(temp.c_str(), final_path.c_str()) != 0) {
    const int err = errno;
    discard();
    fail(destination, "cannot move the finished file into place", err);
  }
  release_slot(slot);
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    ::fsync(dfd);  // best effort: the rename itself has succeeded
    ::close(dfd);
  }
}

}  // namespace penumbra
