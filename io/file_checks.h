// Checks on the files Penumbra reads: every input path is a regular file of bounded size
// before it is opened, so a FIFO, a device node or /dev/zero can never block or flood a read.
// Also the byte-count formatting shared by budget and size messages.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace penumbra {

/// Returns the size of `path` (symlinks followed). Throws InputError(path, element, reason)
/// unless it is a regular file of at most `max_bytes` bytes; the reason says what the path is
/// instead ("does not exist", "is a FIFO, not a regular file", "is 3.0 GiB, over the 2.0 GiB
/// limit"). `element` names the reference in the scene or the option ("buffers[2]", "--env").
uint64_t check_input_file(const std::filesystem::path& path, const std::string& element, uint64_t max_bytes);

/// What kind of file system object `path` is, for messages: "a regular file", "a directory",
/// "a FIFO", "a character device", "a block device", "a socket", "a symbolic link" (only when
/// not followed), "nothing (it does not exist)".
std::string describe_file_type(const std::filesystem::path& path, bool follow_symlinks = true);

/// 1536 -> "1.5 KiB", 3 << 30 -> "3.0 GiB"; below 1 KiB: "512 bytes".
std::string format_bytes(uint64_t bytes);

}  // namespace penumbra
