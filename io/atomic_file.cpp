// Atomic output files.
#include "io/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <cstring>
#include <stdexcept>
#include <string>

namespace penumbra {
namespace {

// A fixed table of temporaries in flight, readable from a signal handler without locks.
constexpr int kSlots = 16;
constexpr size_t kPathMax = 4096;
char g_paths[kSlots][kPathMax];
std::atomic<bool> g_used[kSlots];

int claim_slot(const std::string& path) {
  if (path.size() >= kPathMax) return -1;
  for (int i = 0; i < kSlots; ++i) {
    bool expected = false;
    if (g_used[i].compare_exchange_strong(expected, true)) {
      std::memcpy(g_paths[i], path.c_str(), path.size() + 1);
      return i;
    }
  }
  return -1;
}

void release_slot(int i) {
  if (i >= 0) g_used[i].store(false);
}

}  // namespace

void remove_pending_temporaries() noexcept {
  for (int i = 0; i < kSlots; ++i)
    if (g_used[i].load()) ::unlink(g_paths[i]);
}

void write_atomically(const std::filesystem::path& destination,
                      const std::function<void(const std::filesystem::path&)>& write) {
  static std::atomic<int> counter{0};
  const auto dir = destination.has_parent_path() ? destination.parent_path() : std::filesystem::path(".");
  const auto temp = dir / ("." + destination.stem().string() + ".tmp-" + std::to_string(::getpid()) +
                           "-" + std::to_string(counter++) + destination.extension().string());
  const int slot = claim_slot(temp.string());
  try {
    write(temp);
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove(temp, ec);
    release_slot(slot);
    throw;
  }
  std::error_code ec;
  std::filesystem::rename(temp, destination, ec);
  if (ec) {
    std::filesystem::remove(temp, ec);
    release_slot(slot);
    throw std::runtime_error(destination.string() + ": cannot move the finished file into place: " + ec.message());
  }
  release_slot(slot);
}

}  // namespace penumbra
