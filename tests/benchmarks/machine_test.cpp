// The machine named in benchmark captions, read from files in /proc's format: CPU model, cores
// and hardware threads, memory; and what is said when a file or field is missing.
#include "benchmarks/machine.h"

#include <catch2/catch.hpp>
#include <fstream>

#include "support/test_util.h"

using namespace penumbra;
using namespace penumbra::bench;

TEST_CASE("machine: two sockets of two cores with two threads each", "[bench][quick]") {
  const auto dir = test::temp_dir("machine_info");
  {
    std::ofstream cpu(dir / "cpuinfo");
    for (int p = 0; p < 8; ++p)
      cpu << "processor\t: " << p
          << "\nvendor_id\t: GenuineIntel\nmodel name\t: Intel(R) Xeon(R) Gold 6248R CPU @ "
          << "3.00GHz\nphysical id\t: " << p / 4 << "\nsiblings\t: 4\ncore id\t\t: " << (p % 4) / 2
          << "\ncpu cores\t: 2\nflags\t\t: fpu sse2 avx2\n\n";
    std::ofstream(dir / "meminfo") << "MemTotal:       16318464 kB\nMemFree:         1234 kB\n";
  }
  const MachineInfo m = read_machine_info(dir / "cpuinfo", dir / "meminfo");
  CHECK(m.cpu == "Intel(R) Xeon(R) Gold 6248R CPU @ 3.00GHz");
  CHECK(m.threads == 8);
  CHECK(m.cores == 4);
  CHECK(m.memory_kib == 16318464);
  CHECK(describe(m) == "Intel(R) Xeon(R) Gold 6248R CPU @ 3.00GHz, 4 cores (8 threads), 15.6 GiB RAM");
}

TEST_CASE("machine: missing files and fields are reported as unknown", "[bench][quick]") {
  const auto dir = test::temp_dir("machine_missing");
  const MachineInfo none = read_machine_info(dir / "no-cpuinfo", dir / "no-meminfo");
  CHECK(none.threads == 0);
  CHECK(describe(none) == "unknown CPU, unknown core count, unknown RAM");
  // An ARM-style cpuinfo: processors without model names or core ids.
  std::ofstream(dir / "cpuinfo")
      << "processor\t: 0\nBogoMIPS\t: 50.00\n\nprocessor\t: 1\nBogoMIPS\t: 50.00\n";
  std::ofstream(dir / "meminfo") << "MemFree: 10 kB\n";
  const MachineInfo arm = read_machine_info(dir / "cpuinfo", dir / "meminfo");
  CHECK(describe(arm) == "unknown CPU, 2 hardware threads, unknown RAM");
}

TEST_CASE("machine: this machine's /proc", "[bench][quick]") {
  if (!std::filesystem::exists("/proc/cpuinfo")) return test::skip("no /proc/cpuinfo");
  const MachineInfo m = read_machine_info();
  CHECK(m.threads >= 1);
  CHECK(m.memory_kib > 0);
  CHECK(describe(m).find("GiB RAM") != std::string::npos);
}
