// PLY loader: see ply_loader.h. Format: G. Turk, "The PLY Polygon File Format" (1994).
#include "io/mesh/ply_loader.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "io/files/error.h"
#include "io/files/file_checks.h"

namespace penumbra {
namespace {

enum class Format { Ascii, BinaryLE, BinaryBE };

struct Property {
  std::string name;
  std::string type;        // scalar type, or the item type of a list
  std::string count_type;  // non-empty for a list
};

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> props;
};

int type_size(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

class Reader {
 public:
  Reader(std::ifstream& in, Format f, std::string file) : m_in(in), m_format(f), m_file(std::move(file)) {}

  /// Reads one value of PLY type `t` as a double; `where` names the element for errors.
  double read(const std::string& t, const std::string& where) {
    if (m_format == Format::Ascii) {
      std::string tok;
      if (!(m_in >> tok)) throw InputError(m_file, where, "unexpected end of file");
      char* end = nullptr;
      const double v = std::strtod(tok.c_str(), &end);
      if (end == tok.c_str() || *end != 0) throw InputError(m_file, where, "'" + tok + "' is not a number");
      return v;
    }
    const int n = type_size(t);
    unsigned char b[8];
    if (!m_in.read(reinterpret_cast<char*>(b), n)) throw InputError(m_file, where, "unexpected end of file");
    if ((m_format == Format::BinaryBE) == (std::endian::native == std::endian::little))
      for (int i = 0; i < n / 2; ++i) std::swap(b[i], b[n - 1 - i]);
    auto as = [&](auto v) {
      std::memcpy(&v, b, sizeof v);
      return double(v);
    };
    if (t == "char" || t == "int8") return as(int8_t{});
    if (t == "uchar" || t == "uint8") return as(uint8_t{});
    if (t == "short" || t == "int16") return as(int16_t{});
    if (t == "ushort" || t == "uint16") return as(uint16_t{});
    if (t == "int" || t == "int32") return as(int32_t{});
    if (t == "uint" || t == "uint32") return as(uint32_t{});
    if (t == "float" || t == "float32") return as(float{});
    return as(double{});
  }

 private:
  std::ifstream& m_in;
  Format m_format;
  std::string m_file;
};

std::string format_index(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

/// The header after "ply": format and elements with their properties. Throws InputError naming
/// the header line.
struct Header {
  Format format = Format::Ascii;
  std::vector<Element> elements;
};

Header read_header(std::ifstream& in, const std::string& file) {
  std::string line;
  int line_no = 0;
  auto header_error = [&](const std::string& msg) {
    throw InputError(file, "header line " + std::to_string(line_no), msg);
  };
  auto next_line = [&]() {
    if (!std::getline(in, line)) header_error("unexpected end of file in the header");
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
  };
  Header h;
  next_line();
  if (line != "ply") header_error("not a PLY file (first line must be 'ply')");
  bool have_format = false;
  for (;;) {
    next_line();
    if (line_no > 10000) header_error("header longer than 10000 lines");
    std::istringstream ls(line);
    std::string kw;
    ls >> kw;
    if (kw == "end_header") break;
    if (kw == "comment" || kw == "obj_info" || kw.empty()) continue;
    if (kw == "format") {
      std::string f, v;
      ls >> f >> v;
      if (f == "ascii")
        h.format = Format::Ascii;
      else if (f == "binary_little_endian")
        h.format = Format::BinaryLE;
      else if (f == "binary_big_endian")
        h.format = Format::BinaryBE;
      else
        header_error("unknown format '" + f + "'");
      if (v != "1.0") header_error("unsupported version '" + v + "'");
      have_format = true;
    } else if (kw == "element") {
      Element e;
      long long count = -1;
      if (!(ls >> e.name >> count) || count < 0 || count > (1ll << 31))
        header_error("element needs a name and a count in [0, 2^31]");
      e.count = uint64_t(count);
      h.elements.push_back(e);
    } else if (kw == "property") {
      if (h.elements.empty()) header_error("property before any element");
      Property p;
      std::string t;
      ls >> t;
      if (t == "list") {
        ls >> p.count_type >> p.type >> p.name;
        if (type_size(p.count_type) == 0 || p.count_type.find("float") != std::string::npos ||
            p.count_type == "double")
          header_error("bad list count type '" + p.count_type + "'");
      } else {
        p.type = t;
        ls >> p.name;
      }
      if (type_size(p.type) == 0) header_error("unknown property type '" + p.type + "'");
      if (p.name.empty()) header_error("property without a name");
      h.elements.back().props.push_back(p);
    } else {
      header_error("unknown keyword '" + kw + "'");
    }
  }
  if (!have_format) header_error("no format line");

  return h;
}

/// Reads every element after the header: vertex positions and polygon faces (fanned into
/// triangles) into `mesh`. Throws InputError naming the element and index.
void read_elements(std::ifstream& in, const Header& h, const std::string& file, uint64_t file_bytes,
                   Mesh& mesh) {
  const Format format = h.format;
  Reader r(in, format, file);
  bool have_vertices = false;
  for (const Element& e : h.elements) {
    const bool is_vertex = e.name == "vertex", is_face = e.name == "face";
    int ix = -1, iy = -1, iz = -1, iface = -1;
    for (size_t k = 0; k < e.props.size(); ++k) {
      const auto& p = e.props[k];
      if (is_vertex && p.count_type.empty()) {
        if (p.name == "x") ix = int(k);
        if (p.name == "y") iy = int(k);
        if (p.name == "z") iz = int(k);
      }
      if (is_face && !p.count_type.empty() && (p.name == "vertex_indices" || p.name == "vertex_index"))
        iface = int(k);
    }
    if (is_vertex && (ix < 0 || iy < 0 || iz < 0))
      throw InputError(file, "element vertex", "needs x, y and z properties");
    if (is_face && iface < 0) throw InputError(file, "element face", "needs a vertex_indices list");
    if (is_face && !have_vertices) throw InputError(file, "element face", "comes before element vertex");
    if (is_vertex) {
      // Reserve no more than the rest of the file can hold (a hostile header may claim 2^31
      // vertices): at least 6 bytes per ASCII vertex ("0 0 0\n"), 12 per binary one.
      const uint64_t per_vertex = format == Format::Ascii ? 6 : 12;
      mesh.positions.reserve(size_t(std::min<uint64_t>(e.count, file_bytes / per_vertex)));
      have_vertices = true;
    }
    std::vector<uint32_t> poly;
    for (uint64_t i = 0; i < e.count; ++i) {
      const std::string where = e.name + "[" + std::to_string(i) + "]";
      Vec3f p;
      for (size_t k = 0; k < e.props.size(); ++k) {
        const auto& prop = e.props[k];
        if (prop.count_type.empty()) {
          const double v = r.read(prop.type, where);
          if (int(k) == ix) p.x = float(v);
          if (int(k) == iy) p.y = float(v);
          if (int(k) == iz) p.z = float(v);
          continue;
        }
        const double n = r.read(prop.count_type, where);
        if (!(n >= 0 && n <= 1024 && n == std::floor(n)))
          throw InputError(file, where, "list length must be in [0, 1024]");
        poly.clear();
        for (int j = 0; j < int(n); ++j) {
          const double v = r.read(prop.type, where);
          if (int(k) != iface) continue;
          if (!(v >= 0 && v < double(mesh.positions.size()) && v == std::floor(v)))
            throw InputError(
                file, where,
                "index " + format_index(v) + " >= vertex count " + std::to_string(mesh.positions.size()));
          poly.push_back(uint32_t(v));
        }
        if (int(k) == iface) {
          if (poly.size() < 3) throw InputError(file, where, "a face needs at least 3 vertices");
          for (size_t j = 1; j + 1 < poly.size(); ++j)
            mesh.indices.insert(mesh.indices.end(), {poly[0], poly[j], poly[j + 1]});
        }
      }
      if (is_vertex) {
        if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)))
          throw InputError(file, where, "non-finite coordinate");
        mesh.positions.push_back(p);
      }
    }
  }
}

}  // namespace

namespace {

Scene read_ply(const std::filesystem::path& path, bool points, size_t max_points) {
  const std::string file = path.string();
  const uint64_t file_bytes = check_input_file(path, "", kMaxPlyBytes);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(file, "", "cannot open");
  const Header header = read_header(in, file);
  if (points)
    for (const Element& e : header.elements)
      if (e.name == "vertex" && e.count > max_points)
        throw InputError(
            file, "element vertex",
            std::to_string(e.count) + " vertices exceed the limit of " + std::to_string(max_points));
  Mesh mesh;
  mesh.name = path.stem().string();
  read_elements(in, header, file, file_bytes, mesh);
  Scene scene;
  if (mesh.indices.empty()) {
    if (!points) throw InputError(file, "element face", "no triangles");
    if (mesh.positions.empty()) throw InputError(file, "element vertex", "no vertices");
    add_world_mesh(scene, make_point_set(std::move(mesh.positions), mesh.name));
    return scene;
  }
  mesh.normals = compute_smooth_normals(mesh.positions, mesh.indices);
  add_world_mesh(scene, std::move(mesh));
  return scene;
}

}  // namespace

Scene load_ply(const std::filesystem::path& path) {
  return read_ply(path, false, 0);
}

Scene load_ply_or_points(const std::filesystem::path& path, size_t max_points) {
  return read_ply(path, true, max_points);
}

}  // namespace penumbra
