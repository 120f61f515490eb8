// CheckedFileProxy: pwrite(2) at the proxy's position, fsync and close, each checked.
#include "io/files/checked_file.h"

#include <OpenImageIO/imageio.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace penumbra {

CheckedFileProxy::CheckedFileProxy(const std::filesystem::path& path)
    : OIIO::Filesystem::IOProxy(path.string(), Write) {
  m_fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (m_fd < 0) m_errno = errno;
}

CheckedFileProxy::~CheckedFileProxy() {
  if (m_fd >= 0) ::close(m_fd);
}

void CheckedFileProxy::close() {}  // finish() closes, so that its result is checked

bool CheckedFileProxy::seek(int64_t offset) {
  if (offset < 0) return false;
  m_pos = offset;
  return true;
}

size_t CheckedFileProxy::pwrite(const void* buf, size_t size, int64_t offset) {
  if (m_fd < 0 || m_errno != 0) return 0;
  const auto* p = static_cast<const unsigned char*>(buf);
  size_t done = 0;
  while (done < size) {
    const ssize_t n = ::pwrite(m_fd, p + done, size - done, offset + int64_t(done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      m_errno = n < 0 ? errno : EIO;
      error(std::strerror(m_errno));
      break;
    }
    done += size_t(n);
  }
  m_size = std::max(m_size, offset + int64_t(done));
  return done;
}

size_t CheckedFileProxy::write(const void* buf, size_t size) {
  const size_t n = pwrite(buf, size, m_pos);
  m_pos += int64_t(n);
  return n;
}

void CheckedFileProxy::finish(const std::filesystem::path& shown_as) {
  if (m_fd >= 0) {
    if (m_errno == 0 && ::fsync(m_fd) != 0 && errno != EINVAL) m_errno = errno;
    const int r = ::close(m_fd);
    const int close_errno = errno;
    m_fd = -1;
    if (r != 0 && m_errno == 0) m_errno = close_errno;
  }
  m_mode = Closed;
  if (m_errno != 0) throw std::runtime_error(shown_as.string() + ": write failed: " + std::strerror(m_errno));
}

void write_through_checked_file(std::unique_ptr<OIIO::ImageOutput>& out, const std::filesystem::path& temp,
                                const std::filesystem::path& shown_as, const std::function<void()>& steps) {
  CheckedFileProxy file(temp);
  if (out->supports("ioproxy")) out->set_ioproxy(&file);
  try {
    steps();
  } catch (const std::runtime_error&) {
    out.reset();
    if (file.failed()) file.finish(shown_as);  // the system's reason beats the writer's summary
    throw;
  }
  out.reset();
  file.finish(shown_as);
}

}  // namespace penumbra
