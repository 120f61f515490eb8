// The machine a benchmark ran on, from /proc (benchmarks/machine.h).
#include "benchmarks/machine.h"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <utility>

namespace penumbra::bench {

namespace {

/// Splits "key<spaces/tabs>: value" into its trimmed key and value; false without a colon.
bool split_field(const std::string& line, std::string& key, std::string& value) {
  const size_t colon = line.find(':');
  if (colon == std::string::npos) return false;
  const auto trim = [](std::string s) {
    const size_t b = s.find_first_not_of(" \t"), e = s.find_last_not_of(" \t\r");
    return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
  };
  key = trim(line.substr(0, colon));
  value = trim(line.substr(colon + 1));
  return true;
}

}  // namespace

MachineInfo read_machine_info(const std::filesystem::path& cpuinfo, const std::filesystem::path& meminfo) {
  MachineInfo m;
  std::ifstream c(cpuinfo);
  std::string line, key, value;
  int physical = 0;  // the "physical id" of the current processor entry
  std::set<std::pair<int, int>> cores;
  bool have_model = false;
  while (std::getline(c, line)) {
    if (!split_field(line, key, value)) continue;
    if (key == "processor") {
      ++m.threads;
      physical = 0;
    } else if (key == "model name" && !have_model && !value.empty()) {
      m.cpu = value;
      have_model = true;
    } else if (key == "physical id") {
      physical = std::atoi(value.c_str());
    } else if (key == "core id") {
      cores.insert({physical, std::atoi(value.c_str())});
    }
  }
  m.cores = int(cores.size());
  std::ifstream mem(meminfo);
  while (std::getline(mem, line)) {
    if (!split_field(line, key, value) || key != "MemTotal") continue;
    std::istringstream v(value);
    uint64_t kib = 0;
    if (v >> kib) m.memory_kib = kib;
    break;
  }
  return m;
}

std::string describe(const MachineInfo& m) {
  std::string s = m.cpu;
  if (m.cores > 0 && m.threads > 0)
    s += ", " + std::to_string(m.cores) + (m.cores == 1 ? " core (" : " cores (") +
         std::to_string(m.threads) + (m.threads == 1 ? " thread)" : " threads)");
  else if (m.threads > 0)
    s += ", " + std::to_string(m.threads) + (m.threads == 1 ? " hardware thread" : " hardware threads");
  else
    s += ", unknown core count";
  if (m.memory_kib > 0) {
    char buf[48];
    std::snprintf(buf, sizeof buf, ", %.1f GiB RAM", double(m.memory_kib) / (1024.0 * 1024.0));
    s += buf;
  } else {
    s += ", unknown RAM";
  }
  return s;
}

}  // namespace penumbra::bench
