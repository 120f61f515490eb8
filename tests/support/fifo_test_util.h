// Test helper for inputs that must be refused without being opened: a FIFO that blocks any
// reader until a writer appears.
#pragma once

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <filesystem>
#include <functional>
#include <future>
#include <string>

namespace penumbra::test {

/// Creates a FIFO at `path`.
inline void make_fifo(const std::filesystem::path& path) {
  REQUIRE(::mkfifo(path.c_str(), 0600) == 0);
}

/// Runs `read` (which must throw) on another thread and returns the exception's message, or
/// "no exception". If it is still running after `seconds` (blocked opening `fifo`), the FIFO is
/// opened for writing so the reader sees end of file, and the test fails.
inline std::string message_without_blocking(const std::function<void()>& read,
                                            const std::filesystem::path& fifo, double seconds = 10) {
  auto result = std::async(std::launch::async, [&]() -> std::string {
    try {
      read();
    } catch (const std::exception& e) {
      return e.what();
    }
    return "no exception";
  });
  if (result.wait_for(std::chrono::duration<double>(seconds)) != std::future_status::ready) {
    const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    if (fd >= 0) ::close(fd);
    FAIL("the reader blocked on the FIFO " << fifo);
  }
  return result.get();
}

}  // namespace penumbra::test
