// Input file checks with lstat/stat: nothing is opened before the type and size are known.
// Scene formats by extension and signature (each format's own specification or reference
// writer: Wavefront OBJ, PLY (Turk 1994), STL, FBX, USD, Alembic Ogawa, Blender, COLLADA).
#include "io/files/file_checks.h"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <vector>

#include "io/files/error.h"

namespace penumbra {

namespace {

std::string type_of_mode(mode_t mode) {
  if (S_ISREG(mode)) return "a regular file";
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISLNK(mode)) return "a symbolic link";
  return "not a regular file";
}

/// A 3D format Penumbra does not read, and Blender imports (or opens) and exports as glTF 2.0.
struct SceneFormat {
  const char* name;               ///< "a Wavefront OBJ file"
  std::vector<const char*> exts;  ///< lower case, with the dot
};

const std::vector<SceneFormat>& scene_formats() {
  static const std::vector<SceneFormat> formats = {
      {"a Wavefront OBJ file", {".obj"}},
      {"an FBX file", {".fbx"}},
      {"a USD file", {".usd", ".usda", ".usdc", ".usdz"}},
      {"a PLY (Stanford polygon) file", {".ply"}},
      {"an STL file", {".stl"}},
      {"an Alembic file", {".abc"}},
      {"a Blender file", {".blend"}},
      {"a COLLADA file", {".dae"}},
  };
  return formats;
}

bool starts_with(std::string_view s, std::string_view prefix) {
  return s.substr(0, prefix.size()) == prefix;
}

/// True when the first statement of `text` (after blank lines and '#' comments) is one that
/// starts an OBJ file: a vertex, texture coordinate, normal, face, object, group, smoothing
/// group, line, point or material statement.
bool looks_like_obj(std::string_view text) {
  static const char* kStatements[] = {"v", "vt", "vn", "vp", "f",      "o",
                                      "g", "s",  "l",  "p",  "mtllib", "usemtl"};
  size_t at = 0;
  while (at < text.size()) {
    size_t end = text.find('\n', at);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(at, end - at);
    at = end + 1;
    while (!line.empty() && (line.front() == ' ' || line.front() == '\t')) line.remove_prefix(1);
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.remove_suffix(1);
    if (line.empty() || line.front() == '#') continue;
    const std::string_view word = line.substr(0, line.find_first_of(" \t"));
    if (word.size() == line.size()) return false;  // a statement has arguments
    return std::any_of(std::begin(kStatements), std::end(kStatements),
                       [&](const char* k) { return word == k; });
  }
  return false;
}

/// The format named by the bytes, or empty if none is recognised.
std::string format_by_signature(std::string_view head, uint64_t size) {
  if (starts_with(head, "ply\n") || starts_with(head, "ply\r")) return "a PLY (Stanford polygon) file";
  if (starts_with(head, "Kaydara FBX Binary") || starts_with(head, "; FBX ")) return "an FBX file";
  if (starts_with(head, "#usda ") || starts_with(head, "PXR-USDC")) return "a USD file";
  if (starts_with(head, "Ogawa")) return "an Alembic file";
  if (starts_with(head, "BLENDER")) return "a Blender file";
  if (starts_with(head, "solid ") || starts_with(head, "solid\n") || starts_with(head, "solid\r"))
    return "an STL file";
  if (head.size() >= 84) {  // binary STL: an 80-byte header, a triangle count, 50 bytes per triangle
    uint32_t triangles = 0;
    std::memcpy(&triangles, head.data() + 80, 4);
    if (size == 84 + 50 * uint64_t(triangles)) return "an STL file";
  }
  if (starts_with(head, "PK\x03\x04")) {  // a ZIP archive; USDZ holds a USD layer first
    if (head.size() >= 30) {
      const uint16_t name_length = uint16_t(uint8_t(head[26]) | (uint8_t(head[27]) << 8));
      const std::string_view name = head.substr(30, name_length);
      if (name.find(".usd") != std::string_view::npos) return "a USD file";
    }
    return "a ZIP archive";
  }
  if (starts_with(head, "<?xml") || starts_with(head, "<COLLADA"))
    return head.find("<COLLADA") != std::string_view::npos ? "a COLLADA file" : "an XML file";
  if (starts_with(head, "\x89PNG")) return "a PNG image";
  if (starts_with(head, "\xff\xd8\xff")) return "a JPEG image";
  if (starts_with(head, "v/1\x01")) return "an OpenEXR image";
  if (starts_with(head, "\x89HDF\r\n")) return "an HDF5 file";
  if (starts_with(head, "\x1f\x8b")) return "a gzip-compressed file";
  if (looks_like_obj(head)) return "a Wavefront OBJ file";
  return "";
}

}  // namespace

std::string scene_file_format(const std::filesystem::path& path, std::string_view head, uint64_t size) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  for (const SceneFormat& f : scene_formats())
    for (const char* e : f.exts)
      if (ext == e) return f.name;
  if (starts_with(head, "glTF")) return "";
  std::string_view text = head;
  if (starts_with(text, "\xef\xbb\xbf")) text.remove_prefix(3);  // a UTF-8 byte-order mark
  const size_t first = text.find_first_not_of(" \t\r\n");
  if (first != std::string_view::npos && text[first] == '{') return "";
  const std::string named = format_by_signature(head, size);
  if (!named.empty()) return named;
  return size == 0 ? "an empty file" : "not a glTF file";
}

void check_gltf_file_format(const std::filesystem::path& path, std::string_view head, uint64_t size) {
  const std::string format = scene_file_format(path, head, size);
  if (format.empty()) return;
  std::string what = "this is " + format;
  if (format == "not a glTF file")
    what = "this is not a glTF file: it starts with neither a JSON object nor the GLB magic 'glTF'";
  const auto known = std::find_if(scene_formats().begin(), scene_formats().end(),
                                  [&](const SceneFormat& f) { return format == f.name; });
  std::string hint;
  if (known != scene_formats().end())
    hint = format == "a Blender file"
               ? " — convert it, e.g. with Blender's glTF exporter (open it, then File > Export > glTF 2.0)"
               : " — convert it, e.g. with Blender's glTF exporter (File > Import, then File > Export > glTF "
                 "2.0)";
  throw InputError(path.string(), "", what + "; Penumbra reads glTF 2.0 (.gltf, .glb)" + hint);
}

std::string describe_file_type(const std::filesystem::path& path, bool follow_symlinks) {
  struct stat st {};
  const int r = follow_symlinks ? ::stat(path.c_str(), &st) : ::lstat(path.c_str(), &st);
  if (r != 0) {
    if (errno == ENOENT || errno == ENOTDIR) return "nothing (it does not exist)";
    return std::string("unreadable (") + std::strerror(errno) + ")";
  }
  return type_of_mode(st.st_mode);
}

uint64_t check_input_file(const std::filesystem::path& path, const std::string& element, uint64_t max_bytes) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    const int err = errno;
    if (err == ENOENT || err == ENOTDIR) throw InputError(path.string(), element, "file not found");
    throw InputError(path.string(), element, std::string("cannot access: ") + std::strerror(err));
  }
  if (!S_ISREG(st.st_mode))
    throw InputError(path.string(), element, "is " + type_of_mode(st.st_mode) + ", not a regular file");
  const uint64_t size = uint64_t(st.st_size);
  if (size > max_bytes)
    throw InputError(path.string(), element,
                     "is " + format_bytes(size) + ", over the " + format_bytes(max_bytes) + " limit");
  return size;
}

std::string format_bytes(uint64_t bytes) {
  if (bytes < 1024) return std::to_string(bytes) + " bytes";
  const char* units[] = {"KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  double v = double(bytes) / 1024.0;
  int u = 0;
  while (v >= 1024.0 && u < 5) v /= 1024.0, ++u;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f %s", v, units[u]);
  return buf;
}

}  // namespace penumbra
