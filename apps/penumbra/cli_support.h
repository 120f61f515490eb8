// What every `penumbra` subcommand shares: the usage error and the exit codes, strict parsers
// for the numbers, sizes and colours on the command line, text formatting without fixed-size
// buffers, the clock, and the memory figures of the process.
#pragma once

#include <chrono>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include "renderer/core/math.h"

namespace penumbra::cli {

inline constexpr int kExitOk = 0;        ///< success
inline constexpr int kExitInternal = 1;  ///< a failure outside the input (I/O, memory)
inline constexpr int kExitInput = 2;     ///< bad input or usage

/// Bad command-line values: reported like bad files, exit 2.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0);

/// What the program is doing now ("loading the scene"), for the out-of-memory message.
void set_phase(const char* phase);
const char* current_phase();

/// A decimal integer in [lo, hi]: digits only (a leading '-' only if lo < 0), no spaces, no
/// wrap-around. Throws UsageError naming `option` and the valid range otherwise.
long long parse_integer(std::string_view text, long long lo, long long hi, const std::string& option);

/// Splits "a<sep>b" into exactly two parts; throws UsageError with `expected` otherwise.
std::pair<std::string, std::string> split_pair(const std::string& text, char sep, const std::string& option,
                                               const std::string& expected);

/// "512M", "4G", "1073741824" -> bytes (K, M, G are powers of 1024). Throws UsageError naming
/// --max-memory for anything else or a value outside (0, 10^15].
uint64_t parse_bytes(const std::string& s);

/// Half the machine's RAM (8 GiB if it cannot be read).
uint64_t default_memory_budget();

/// --max-memory's value, or the default when `text` is empty.
uint64_t memory_budget(const std::string& text);

/// "r,g,b" or a single grey value, each finite and >= 0. Throws UsageError naming `option`.
Vec3f parse_colour(const std::string& s, const char* option);

/// printf-style formatting into a string of whatever length the result needs.
std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

/// 1234567 -> "1.23M", 4646 -> "4.6k", 12 -> "12".
std::string human_count(uint64_t n);

/// A number as text that reads back to the same double ("%.17g").
std::string exact(double v);

/// The process's peak resident memory in MiB.
double peak_memory_mib();

}  // namespace penumbra::cli
