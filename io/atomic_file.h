// Atomic file output: write to a hidden temporary beside the destination, then rename().
// A failed or interrupted run never leaves a half-written image under the final name.
#pragma once

#include <filesystem>
#include <functional>

namespace penumbra {

/// Calls write(temp_path) and renames temp_path to `destination` if it returns normally.
/// The temporary ("<dir>/.<name>.tmp-<pid>-<n><ext>", same extension so format detection
/// still works) is removed if write throws, and by remove_pending_temporaries() from a signal
/// handler. Throws std::runtime_error if the rename fails.
void write_atomically(const std::filesystem::path& destination,
                      const std::function<void(const std::filesystem::path&)>& write);

/// Unlinks every temporary currently being written. Async-signal-safe (SIGINT/SIGTERM).
void remove_pending_temporaries() noexcept;

}  // namespace penumbra
