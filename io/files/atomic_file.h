// Output files that never lose data. A regular-file target is written to a hidden temporary
// beside it, synced and renamed into place, so a failed or interrupted run leaves the old file
// untouched; a symlink's target is replaced the same way; character devices and FIFOs
// (/dev/stdout, a pipe) are streamed to; directories, sockets and block devices are refused.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace penumbra {

/// How an output path is written.
enum class OutputKind {
  Replace,  ///< a regular file, or nothing yet: temporary + fsync + rename (atomic)
  Stream,   ///< a character device, FIFO or open descriptor: bytes written through, in order
};

/// Where and how an output path ends up. Symlinks are resolved: `target` is the file that is
/// replaced or streamed to.
struct OutputTarget {
  OutputKind kind = OutputKind::Replace;
  std::filesystem::path target;  ///< the resolved file (for Stream with fd >= 0: the path given)
  int fd = -1;                   ///< an already open descriptor (/dev/stdout, /dev/fd/N), else -1
  dev_t device = 0;              ///< identity of the existing file (0, 0: it does not exist yet)
  ino_t inode = 0;
};

/// Classifies `destination` without writing anything. Throws InputError naming the path (as
/// `element`, e.g. "--stats-json") if it is a directory, socket or block device, if its folder
/// does not exist, or if a symlink chain is longer than 40 links.
OutputTarget resolve_output(const std::filesystem::path& destination, const std::string& element = "");

/// Throws InputError if two of the named paths (option name, path) are the same file once
/// symlinks and relative paths are resolved (a hard link counts as the same file). Inputs are
/// compared against outputs too, so that no output can overwrite a file the run reads.
void check_distinct_files(const std::vector<std::pair<std::string, std::filesystem::path>>& outputs,
                          const std::vector<std::pair<std::string, std::filesystem::path>>& inputs = {});

/// Calls write(temp_path) and moves the result to `destination` if it returns normally: by an
/// fsync'ed rename for Replace targets (the mode of a replaced file is kept), by copying the
/// bytes for Stream targets. The temporary ("<dir>/.<name>.tmp-<pid>-<n><ext>", same extension
/// so format detection still works; for streams in the system's temporary folder) is removed if
/// anything fails, and by remove_pending_temporaries() from a signal handler. If `sha256` is not
/// null it receives the SHA-256 of the bytes written. Throws InputError for a refused target and
/// std::runtime_error with the system's reason for any failed create, write, sync, close or
/// rename; the destination is unchanged then.
void write_atomically(const std::filesystem::path& destination,
                      const std::function<void(const std::filesystem::path&)>& write,
                      std::string* sha256 = nullptr);

/// Writes `bytes` to `path` with checked write(2) calls, fsync and close; throws
/// std::runtime_error naming `shown_as` (default: `path`) and the system's reason on failure.
void write_file_checked(const std::filesystem::path& path, const void* bytes, size_t size,
                        const std::filesystem::path& shown_as = {});

/// Unlinks every temporary currently being written. Async-signal-safe (SIGINT/SIGTERM).
void remove_pending_temporaries() noexcept;

}  // namespace penumbra
