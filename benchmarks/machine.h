// The machine a benchmark ran on, as a figure caption names it: CPU model, cores and hardware
// threads, memory. Read from Linux's /proc/cpuinfo and /proc/meminfo (other paths for tests);
// what a file does not say is reported as unknown, never guessed.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace penumbra::bench {

struct MachineInfo {
  std::string cpu = "unknown CPU";  ///< the first "model name" of cpuinfo
  int threads = 0;                  ///< hardware threads: "processor" entries (0: unknown)
  int cores = 0;                    ///< distinct (physical id, core id) pairs (0: unknown)
  uint64_t memory_kib = 0;          ///< MemTotal (0: unknown)
};

/// The machine described by `cpuinfo` and `meminfo` (files in /proc's format). Missing files or
/// fields leave the defaults; never throws for their content.
MachineInfo read_machine_info(const std::filesystem::path& cpuinfo = "/proc/cpuinfo",
                              const std::filesystem::path& meminfo = "/proc/meminfo");

/// One line for a caption, e.g. "AMD EPYC, 2 cores (2 threads), 23.5 GiB RAM".
std::string describe(const MachineInfo& m);

}  // namespace penumbra::bench
