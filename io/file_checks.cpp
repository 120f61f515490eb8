// Input file checks with lstat/stat: nothing is opened before the type and size are known.
#include "io/file_checks.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "io/error.h"

namespace penumbra {

namespace {

std::string type_of_mode(mode_t mode) {
  if (S_ISREG(mode)) return "a regular file";
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISLNK(mode)) return "a symbolic link";
  return "not a regular file";
}

}  // namespace

std::string describe_file_type(const std::filesystem::path& path, bool follow_symlinks) {
  struct stat st {};
  const int r = follow_symlinks ? ::stat(path.c_str(), &st) : ::lstat(path.c_str(), &st);
  if (r != 0) {
    if (errno == ENOENT || errno == ENOTDIR) return "nothing (it does not exist)";
    return std::string("unreadable (") + std::strerror(errno) + ")";
  }
  return type_of_mode(st.st_mode);
}

uint64_t check_input_file(const std::filesystem::path& path, const std::string& element, uint64_t max_bytes) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    const int err = errno;
    if (err == ENOENT || err == ENOTDIR) throw InputError(path.string(), element, "file not found");
    throw InputError(path.string(), element, std::string("cannot access: ") + std::strerror(err));
  }
  if (!S_ISREG(st.st_mode))
    throw InputError(path.string(), element, "is " + type_of_mode(st.st_mode) + ", not a regular file");
  const uint64_t size = uint64_t(st.st_size);
  if (size > max_bytes)
    throw InputError(path.string(), element,
                     "is " + format_bytes(size) + ", over the " + format_bytes(max_bytes) + " limit");
  return size;
}

std::string format_bytes(uint64_t bytes) {
  if (bytes < 1024) return std::to_string(bytes) + " bytes";
  const char* units[] = {"KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  double v = double(bytes) / 1024.0;
  int u = 0;
  while (v >= 1024.0 && u < 5) v /= 1024.0, ++u;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f %s", v, units[u]);
  return buf;
}

}  // namespace penumbra
