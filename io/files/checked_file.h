// An OpenImageIO output proxy over a POSIX file descriptor that checks every write and the
// close. OIIO's own file proxy writes through stdio and ignores fclose's result, so the last
// buffered bytes of an EXR or PNG could be lost to a full disk without an error; through this
// proxy every failure is kept with its errno and reported.
#pragma once

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <filesystem>
#include <functional>
#include <memory>

namespace penumbra {

class CheckedFileProxy : public OIIO::Filesystem::IOProxy {
 public:
  /// Creates or truncates `path` for writing. A failure to open is reported by finish().
  explicit CheckedFileProxy(const std::filesystem::path& path);
  ~CheckedFileProxy() override;
  CheckedFileProxy(const CheckedFileProxy&) = delete;
  CheckedFileProxy& operator=(const CheckedFileProxy&) = delete;

  const char* proxytype() const override { return "checked-file"; }
  void close() override;
  bool seek(int64_t offset) override;
  size_t write(const void* buf, size_t size) override;
  size_t pwrite(const void* buf, size_t size, int64_t offset) override;
  size_t size() const override { return size_t(m_size); }

  /// True once an open, write or close has failed.
  bool failed() const { return m_errno != 0; }
  /// Closes the file (fsync first) and throws std::runtime_error naming `shown_as` with the
  /// system's reason if anything failed. Call once, after the image writer has closed.
  void finish(const std::filesystem::path& shown_as);

 private:
  int m_fd = -1;
  int m_errno = 0;  ///< the first failure's errno
  int64_t m_size = 0;
};

/// Runs `steps` (the writer's open, write and close calls, throwing std::runtime_error on a
/// failure) with `out` writing `temp` through a CheckedFileProxy when the format supports one
/// (OpenEXR, PNG, JPEG and TIFF do in OpenImageIO 2.4). `out` is destroyed before the proxy,
/// also on failure (a writer's destructor may still write). Throws std::runtime_error naming
/// `shown_as`: with the system's reason when a write, sync or close failed, else what `steps`
/// threw.
void write_through_checked_file(std::unique_ptr<OIIO::ImageOutput>& out, const std::filesystem::path& temp,
                                const std::filesystem::path& shown_as, const std::function<void()>& steps);

}  // namespace penumbra
