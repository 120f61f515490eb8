// Point files; see points_file.h.
#include "io/files/points_file.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>

#include "io/files/error.h"

namespace penumbra {

std::vector<Vec3f> read_points_file(const std::string& path, size_t max_points) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "", "cannot be read");
  std::vector<Vec3f> points;
  std::string line;
  size_t number = 0;
  while (std::getline(in, line)) {
    ++number;
    const std::string element = "line " + std::to_string(number);
    if (line.size() > 4096) throw InputError(path, element, "is longer than 4096 characters");
    size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    for (char& c : line)
      if (c == ',' || c == '\t' || c == '\r') c = ' ';
    float v[3];
    const char* s = line.c_str();
    for (int k = 0; k < 3; ++k) {
      char* end = nullptr;
      errno = 0;
      const double d = std::strtod(s, &end);
      if (end == s || errno == ERANGE || !std::isfinite(d) || std::fabs(d) > 3.0e38)
        throw InputError(path, element, "is not three finite numbers x y z");
      v[k] = float(d);
      s = end;
    }
    while (*s == ' ') ++s;
    if (*s != '\0') throw InputError(path, element, "has more than three numbers (x y z per line)");
    if (points.size() == max_points)
      throw InputError(path, element, "exceeds the limit of " + std::to_string(max_points) + " points");
    points.push_back({v[0], v[1], v[2]});
  }
  if (in.bad()) throw InputError(path, "", "cannot be read");
  if (points.empty()) throw InputError(path, "", "holds no point (x y z per line)");
  return points;
}

namespace {

constexpr char kNpyMagic[] = "\x93NUMPY";

// The value of key `key` in an .npy header dictionary ("{'descr': '<f8', ...}"), up to the next
// top-level comma or the closing brace; empty if absent.
std::string npy_field(const std::string& header, const std::string& key) {
  const size_t at = header.find("'" + key + "'");
  if (at == std::string::npos) return {};
  size_t p = header.find(':', at);
  if (p == std::string::npos) return {};
  ++p;
  int depth = 0;
  size_t end = p;
  for (; end < header.size(); ++end) {
    const char c = header[end];
    if (c == '(') ++depth;
    if (c == ')') --depth;
    if ((c == ',' && depth == 0) || (c == '}' && depth <= 0)) break;
  }
  std::string v = header.substr(p, end - p);
  v.erase(std::remove(v.begin(), v.end(), ' '), v.end());
  return v;
}

}  // namespace

std::vector<Vec3f> read_npy_points(const std::string& path, size_t max_points) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", "cannot be read");
  char magic[8] = {};
  in.read(magic, 8);
  if (!in || std::memcmp(magic, kNpyMagic, 6) != 0)
    throw InputError(path, "header", "is not a NumPy .npy file");
  const int major = static_cast<unsigned char>(magic[6]);
  if (major < 1 || major > 3)
    throw InputError(path, "header", "format version " + std::to_string(major) + " is not 1, 2 or 3");
  unsigned char len_bytes[4] = {};
  in.read(reinterpret_cast<char*>(len_bytes), major == 1 ? 2 : 4);
  const uint64_t header_len = major == 1 ? uint64_t(len_bytes[0]) | uint64_t(len_bytes[1]) << 8
                                         : uint64_t(len_bytes[0]) | uint64_t(len_bytes[1]) << 8 |
                                               uint64_t(len_bytes[2]) << 16 | uint64_t(len_bytes[3]) << 24;
  if (!in || header_len > 65536) throw InputError(path, "header", "is truncated or longer than 64 KiB");
  std::string header(header_len, '\0');
  in.read(header.data(), std::streamsize(header_len));
  if (!in) throw InputError(path, "header", "is truncated");
  const std::string descr = npy_field(header, "descr"), order = npy_field(header, "fortran_order"),
                    shape = npy_field(header, "shape");
  if (descr != "'<f4'" && descr != "'<f8'")
    throw InputError(path, "header",
                     "dtype " + descr + " is not little-endian float32 ('<f4') or float64 ('<f8')");
  if (order != "False")
    throw InputError(path, "header", "the array is not in C order (fortran_order is " + order + ")");
  // "(N,3)" or "(3,)".
  uint64_t rows = 0;
  if (shape == "(3,)") {
    rows = 1;
  } else {
    char* end = nullptr;
    errno = 0;
    const unsigned long long n =
        shape.size() > 2 && shape[0] == '(' ? std::strtoull(shape.c_str() + 1, &end, 10) : 0;
    if (!end || errno == ERANGE || std::string(end) != ",3)")
      throw InputError(path, "header", "shape " + shape + " is not (N, 3)");
    rows = n;
  }
  if (rows == 0) throw InputError(path, "header", "holds no point");
  if (rows > max_points)
    throw InputError(
        path, "header",
        std::to_string(rows) + " points exceed the limit of " + std::to_string(max_points) + " points");
  const size_t size = descr == "'<f4'" ? 4 : 8;
  std::vector<char> data(size_t(rows) * 3 * size);
  in.read(data.data(), std::streamsize(data.size()));
  if (in.gcount() != std::streamsize(data.size()))
    throw InputError(path, "",
                     "is truncated: " + std::to_string(rows) + " rows need " + std::to_string(data.size()) +
                         " bytes of data");
  std::vector<Vec3f> points(rows);
  for (size_t i = 0; i < rows; ++i) {
    double v[3];
    for (int k = 0; k < 3; ++k) {
      const char* at = data.data() + (3 * i + size_t(k)) * size;
      if (size == 4) {
        float f;
        std::memcpy(&f, at, 4);
        v[k] = f;
      } else {
        std::memcpy(&v[k], at, 8);
      }
      if (!std::isfinite(v[k]) || std::fabs(v[k]) > 3.0e38)
        throw InputError(path, "row " + std::to_string(i), "is not three finite numbers within float range");
    }
    points[i] = {float(v[0]), float(v[1]), float(v[2])};
  }
  return points;
}

std::vector<Vec3f> read_query_points(const std::string& path, size_t max_points) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", "cannot be read");
  char magic[6] = {};
  in.read(magic, 6);
  if (in.gcount() == 6 && std::memcmp(magic, kNpyMagic, 6) == 0) return read_npy_points(path, max_points);
  return read_points_file(path, max_points);
}

}  // namespace penumbra
