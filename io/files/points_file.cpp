// Text point files; see points_file.h.
#include "io/files/points_file.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
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

}  // namespace penumbra
