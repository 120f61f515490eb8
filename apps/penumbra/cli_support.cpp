// Parsers and formatting shared by the subcommands.
#include "apps/penumbra/cli_support.h"

#include <sys/resource.h>
#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <sstream>
#include <vector>

namespace penumbra::cli {

namespace {
const char* g_phase = "parsing the command line";
}  // namespace

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

void set_phase(const char* phase) {
  g_phase = phase;
}
const char* current_phase() {
  return g_phase;
}

long long parse_integer(std::string_view text, long long lo, long long hi, const std::string& option) {
  long long v = 0;
  const char* end = text.data() + text.size();
  const auto r = std::from_chars(text.data(), end, v);
  if (text.empty() || r.ptr != end || (r.ec != std::errc() && r.ec != std::errc::result_out_of_range) ||
      text[0] == '+' || (text[0] == '-' && lo >= 0))
    throw UsageError(option + ": '" + std::string(text) + "' is not an integer");
  if (r.ec == std::errc::result_out_of_range || v < lo || v > hi)
    throw UsageError(option + ": " + std::string(text) + " is outside [" + std::to_string(lo) + ", " +
                     std::to_string(hi) + "]");
  return v;
}

std::pair<std::string, std::string> split_pair(const std::string& text, char sep, const std::string& option,
                                               const std::string& expected) {
  const size_t at = text.find(sep);
  if (at == std::string::npos || text.find(sep, at + 1) != std::string::npos)
    throw UsageError(option + ": expected " + expected + ", got '" + text + "'");
  return {text.substr(0, at), text.substr(at + 1)};
}

uint64_t parse_bytes(const std::string& s) {
  size_t pos = 0;
  double v = 0;
  try {
    v = std::stod(s, &pos);
  } catch (...) {
    throw UsageError("--max-memory: cannot parse '" + s + "'");
  }
  const std::string unit = s.substr(pos);
  double mul = 1;
  if (unit == "K" || unit == "k")
    mul = 1024.0;
  else if (unit == "M" || unit == "m")
    mul = 1024.0 * 1024;
  else if (unit == "G" || unit == "g")
    mul = 1024.0 * 1024 * 1024;
  else if (!unit.empty())
    throw UsageError("--max-memory: unknown unit '" + unit + "' (use K, M or G)");
  if (!(v > 0) || !std::isfinite(v * mul) || v * mul > 1e15)
    throw UsageError("--max-memory: out of range: " + s);
  return uint64_t(v * mul);
}

uint64_t default_memory_budget() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || page <= 0) return 8ull << 30;
  return uint64_t(pages) * uint64_t(page) / 2;
}

uint64_t memory_budget(const std::string& text) {
  return text.empty() ? default_memory_budget() : parse_bytes(text);
}

Vec3f parse_colour(const std::string& s, const char* option) {
  std::vector<float> v;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      size_t pos = 0;
      v.push_back(std::stof(item, &pos));
      if (pos != item.size()) throw std::invalid_argument(item);
    } catch (...) {
      throw UsageError(std::string(option) + ": cannot parse '" + s + "' (expected r,g,b or one value)");
    }
  }
  if (v.size() == 1) v = {v[0], v[0], v[0]};
  if (v.size() != 3) throw UsageError(std::string(option) + ": expected r,g,b or one value, got '" + s + "'");
  for (float x : v)
    if (!std::isfinite(x) || x < 0)
      throw UsageError(std::string(option) + ": values must be finite and >= 0");
  return {v[0], v[1], v[2]};
}

std::string format(const char* fmt, ...) {
  va_list args;
  va_start(args, fmt);
  va_list again;
  va_copy(again, args);
  const int n = std::vsnprintf(nullptr, 0, fmt, args);
  va_end(args);
  std::string out(n > 0 ? size_t(n) : 0, '\0');
  if (n > 0) std::vsnprintf(out.data(), out.size() + 1, fmt, again);
  va_end(again);
  return out;
}

std::string human_count(uint64_t n) {
  if (n >= 1000000) return format("%.2fM", double(n) / 1e6);
  if (n >= 1000) return format("%.1fk", double(n) / 1e3);
  return std::to_string(n);
}

std::string exact(double v) {
  return format("%.17g", v);
}

double peak_memory_mib() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return double(ru.ru_maxrss) / 1024.0;  // ru_maxrss is KiB on Linux
}

}  // namespace penumbra::cli
