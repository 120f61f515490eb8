// glTF file access: bounded non-blocking reads, the GLB chunk walk, URI resolution and the
// sandboxed file callbacks tinygltf parses with.
#include "io/gltf/file_access.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <tiny_gltf.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "io/files/error.h"
#include "io/files/file_checks.h"
#include "io/files/hash.h"

namespace penumbra::gltf {

namespace fs = std::filesystem;

std::vector<unsigned char> read_input_file(const fs::path& path, const std::string& element,
                                           uint64_t max_bytes, uint64_t prefix_bytes) {
  check_input_file(path, element, max_bytes);
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw InputError(path.string(), element, std::string("cannot open: ") + std::strerror(errno));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))
    throw InputError(path.string(), element, "is " + describe_file_type(path) + ", not a regular file");
  const uint64_t size = uint64_t(st.st_size);
  if (size > max_bytes)
    throw InputError(path.string(), element,
                     "is " + format_bytes(size) + ", over the " + format_bytes(max_bytes) + " limit");
  std::vector<unsigned char> out(size_t(std::min(size, prefix_bytes)));
  size_t done = 0;
  while (done < out.size()) {
    const ssize_t n = ::read(fd, out.data() + done, out.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw InputError(path.string(), element, std::string("read failed: ") + std::strerror(errno));
    if (n == 0) throw InputError(path.string(), element, "file shrank while it was read");
    done += size_t(n);
  }
  return out;
}

GlbLayout parse_glb(const std::string& file, std::span<const unsigned char> bytes) {
  constexpr uint32_t kJson = 0x4E4F534Au, kBin = 0x004E4942u;  // "JSON", "BIN\0" little-endian
  auto u32 = [&](uint64_t off) {
    uint32_t v;
    std::memcpy(&v, bytes.data() + off, 4);
    return v;
  };
  if (bytes.size() < 12) throw InputError(file, "GLB header", "file too short for a GLB header");
  if (u32(4) != 2) throw InputError(file, "GLB header", "version " + std::to_string(u32(4)) + " is not 2");
  const uint64_t total = u32(8);
  if (total > bytes.size())
    throw InputError(
        file, "GLB header",
        "declared length " + std::to_string(total) + " exceeds file size " + std::to_string(bytes.size()));
  GlbLayout out;
  bool has_json = false, has_bin = false;
  uint64_t off = 12;
  for (int i = 0; off < total; ++i) {
    const std::string where = "GLB chunk " + std::to_string(i);
    if (off + 8 > total)
      throw InputError(file, where,
                       "truncated chunk header (" + std::to_string(total - off) + " bytes left)");
    const uint64_t length = u32(off), type = u32(off + 4), end = off + 8 + length;
    if (end > total)
      throw InputError(file, where,
                       "chunk length " + std::to_string(length) + " exceeds the file (" +
                           std::to_string(total - off - 8) + " bytes left)");
    if (length % 4 != 0)
      throw InputError(file, where,
                       "chunk length " + std::to_string(length) +
                           " is not a multiple of 4 (chunks must end on a 4-byte boundary)");
    if (i == 0) {
      if (type != kJson) throw InputError(file, where, "first chunk is not JSON");
      out.json = {reinterpret_cast<const char*>(bytes.data()) + off + 8, size_t(length)};
      out.kept_length = end;
      has_json = true;
    } else if (type == kBin) {
      if (has_bin) throw InputError(file, where, "a second BIN chunk (a GLB holds at most one)");
      if (i != 1) throw InputError(file, where, "the BIN chunk must be the second chunk");
      out.bin_bytes = length;
      out.kept_length = end;
      has_bin = true;
    } else if (type == kJson) {
      throw InputError(file, where, "a second JSON chunk (a GLB holds exactly one)");
    } else {
      char name[64];
      std::snprintf(name, sizeof name, "unknown chunk type 0x%08x", unsigned(type));
      out.warnings.push_back(where + ": " + name + " (" + std::to_string(length) + " bytes) ignored");
    }
    off = end;
  }
  if (!has_json) throw InputError(file, "GLB chunk 0", "missing (a GLB must start with a JSON chunk)");
  return out;
}

bool is_data_uri(std::string_view uri) {
  return uri.substr(0, 5) == "data:";
}

std::string decode_uri(std::string_view uri) {
  auto hex = [](char c) -> unsigned {
    if (c >= '0' && c <= '9') return unsigned(c - '0');
    if (c >= 'a' && c <= 'f') return unsigned(c - 'a' + 10);
    if (c >= 'A' && c <= 'F') return unsigned(c - 'A' + 10);
    return 0;
  };
  std::string out;
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '+') {
      out += ' ';
    } else if (uri[i] == '%' && uri.size() > i + 2) {
      out += char((hex(uri[i + 1]) << 4) | hex(uri[i + 2]));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

ResolvedUri resolve_uri(const std::string& uri, const fs::path& root, bool allow_external,
                        uint64_t max_bytes) {
  const fs::path decoded(decode_uri(uri));
  const fs::path target = decoded.is_absolute() ? decoded : root / decoded;
  std::error_code ec;
  ResolvedUri out;
  out.path = fs::weakly_canonical(target, ec);
  if (ec) out.path = target.lexically_normal();
  if (!allow_external) {
    const fs::path rel = out.path.lexically_relative(root);
    if (rel.empty() || *rel.begin() == "..") {
      out.refusal = "refused by policy: it resolves to '" + out.path.string() +
                    "', outside the scene folder '" + root.string() +
                    "' (use --allow-external-uris to permit)";
      out.by_policy = true;
      return out;
    }
  }
  try {
    out.size = check_input_file(out.path, "", max_bytes);
  } catch (const InputError& e) {
    out.refusal = e.what();
  }
  return out;
}

namespace {

bool sandbox_file_exists(const std::string& path, void* user) {
  return static_cast<FileSandbox*>(user)->served.count(path) > 0;
}

std::string sandbox_expand(const std::string& path, void*) {
  return path;
}  // no ~ or $VAR

bool sandbox_read(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  auto& box = *static_cast<FileSandbox*>(user);
  const auto it = box.served.find(path);
  if (it == box.served.end()) {
    if (err) *err = "not a file the loader checked";
    return false;
  }
  try {
    *out = read_input_file(it->second, "", box.max_bytes);
  } catch (const InputError& e) {
    if (err) *err = e.what();
    return false;
  }
  if (std::find(box.read->begin(), box.read->end(), it->second) == box.read->end()) {
    box.read->push_back(it->second);
    if (box.read_sha256)
      box.read_sha256->push_back(sha256_hex({reinterpret_cast<const char*>(out->data()), out->size()}));
  }
  return true;
}

bool sandbox_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err = "writing is not allowed";
  return false;
}

}  // namespace

std::string sandbox_name(const std::string& base, const std::string& decoded_uri) {
  if (base.empty()) return decoded_uri;
  return base.back() == '/' ? base + decoded_uri : base + "/" + decoded_uri;
}

void install_sandbox(tinygltf::TinyGLTF& parser, FileSandbox& box) {
  parser.SetFsCallbacks({sandbox_file_exists, sandbox_expand, sandbox_read, sandbox_write, &box});
}

}  // namespace penumbra::gltf
