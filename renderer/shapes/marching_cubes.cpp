// Marching cubes without case tables: per cell, the crossings of each face are joined into
// oriented segments (Nielson & Hamann's asymptotic decider on faces with four crossings), the
// segments close into loops and each loop is triangulated. Three parallel passes (grid values
// by blocks; vertex and triangle counts per grid row; each row filled at its prefix-sum offsets),
// so the output is the same for any thread count.
#include "renderer/shapes/marching_cubes.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <bit>
#include <cassert>
#include <cmath>
#include <stdexcept>
#include <string>

namespace penumbra {

namespace {

// Cube corner c = dx | dy << 1 | dz << 2. Edge e = 4 a + q runs along axis a from corner
// edge_corner[e][0] to edge_corner[e][1]; q holds the offsets along the two other axes (lower
// axis in bit 0). Face f = 2 a + s is the face at offset s along axis a; its corners are listed
// counter-clockwise seen from outside the cell and face_edge[f][m] joins corners m and m + 1.
struct CubeTables {
  int edge_corner[12][2] = {};
  int face_corner[6][4] = {};
  int face_edge[6][4] = {};
  bool same_face[12][12] = {};  // the two edges lie on a common face
};

constexpr int edge_between(int c0, int c1) {
  const int a = std::countr_zero(unsigned(c0 ^ c1));
  const int lo = c0 & c1;
  const int u = a == 0 ? 1 : 0, v = a == 2 ? 1 : 2;
  return 4 * a + (((lo >> u) & 1) | (((lo >> v) & 1) << 1));
}

constexpr CubeTables make_cube_tables() {
  CubeTables t;
  for (int e = 0; e < 12; ++e) {
    const int a = e / 4, q = e % 4;
    const int u = a == 0 ? 1 : 0, v = a == 2 ? 1 : 2;
    t.edge_corner[e][0] = ((q & 1) << u) | ((q >> 1) << v);
    t.edge_corner[e][1] = t.edge_corner[e][0] | (1 << a);
  }
  for (int f = 0; f < 6; ++f) {
    const int a = f / 2, s = f % 2;
    const int u = (a + 1) % 3, v = (a + 2) % 3;  // right-handed: e_u x e_v = e_a
    const int ccw[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int m = 0; m < 4; ++m) {
      const int k = s ? m : (4 - m) % 4;  // seen from -e_a the order reverses
      t.face_corner[f][m] = (s << a) | (ccw[k][0] << u) | (ccw[k][1] << v);
    }
    for (int m = 0; m < 4; ++m)
      t.face_edge[f][m] = edge_between(t.face_corner[f][m], t.face_corner[f][(m + 1) % 4]);
    for (int m = 0; m < 4; ++m)
      for (int n = 0; n < 4; ++n) t.same_face[t.face_edge[f][m]][t.face_edge[f][n]] = true;
  }
  return t;
}

constexpr CubeTables kCube = make_cube_tables();

// Set bits of a 3-bit mask (std::popcount is a library call on portable x86-64).
constexpr int kBitCount[8] = {0, 1, 1, 2, 1, 2, 2, 3};

bool inside(float f) {
  return f < 0;  // f >= 0 and NaN are outside
}

// Where an edge's crossing lies by linear interpolation, as a fraction from its first corner.
float crossing_fraction(float f0, float f1) {
  const float t = f0 / (f0 - f1);
  return t >= 0 && t <= 1 ? t : 0.5f;
}

// One cell's share of the surface in local vertex ids: 0-11 the crossings of the cell's edges,
// 12 + c the c-th extra vertex at the centre of the loop loop_edges[centre_begin[c], centre_end[c]).
struct CellSurface {
  int triangle_count = 0;
  uint8_t triangles[12][3] = {};
  int centre_count = 0;
  uint8_t centre_begin[4] = {}, centre_end[4] = {};
  uint8_t loop_edges[12] = {};
};

// Joins each face's crossings into segments directed so the outside lies to their left seen
// from outside the cell; next[e] is the crossing the segment leaving crossing e goes to.
// A crossing on edge m of a face starts a segment when the face's corner m + 1 is inside.
void join_face_crossings(const float f[8], int next[12]) {
  for (int face = 0; face < 6; ++face) {
    const int* c = kCube.face_corner[face];
    int starts[2], ends[2], ns = 0, ne = 0, start_m[2] = {};
    for (int m = 0; m < 4; ++m) {
      const bool in0 = inside(f[c[m]]), in1 = inside(f[c[(m + 1) % 4]]);
      if (in0 == in1) continue;
      if (in1) {
        start_m[ns] = m;
        starts[ns++] = kCube.face_edge[face][m];
      } else {
        ends[ne++] = kCube.face_edge[face][m];
      }
    }
    if (ns == 1) {
      next[starts[0]] = ends[0];
    } else if (ns == 2) {
      // Asymptotic decider: the bilinear interpolant's saddle value (f0 f2 - f1 f3) /
      // (f0 + f2 - f1 - f3) is >= 0 exactly when the outside diagonal's product is at least the
      // inside one's; then the outside corners connect and each segment cuts off an inside
      // corner. Products commute, so both cells sharing the face decide alike.
      const double p02 = double(f[c[0]]) * double(f[c[2]]), p13 = double(f[c[1]]) * double(f[c[3]]);
      const bool outside_is_02 = !inside(f[c[0]]);
      const bool outside_connected = outside_is_02 ? p02 >= p13 : p13 >= p02;
      for (int s = 0; s < 2; ++s) {
        const int m = start_m[s];
        next[starts[s]] = kCube.face_edge[face][outside_connected ? (m + 1) % 4 : (m + 3) % 4];
      }
    }
  }
}

// Crossing positions by linear interpolation in the unit cube (for choosing triangulations; a
// function of the corner values alone, so every pass chooses alike).
Vec3f local_crossing(const float f[8], int e) {
  const int c0 = kCube.edge_corner[e][0];
  Vec3f p{float(c0 & 1), float((c0 >> 1) & 1), float((c0 >> 2) & 1)};
  p[e / 4] = crossing_fraction(f[c0], f[kCube.edge_corner[e][1]]);
  return p;
}

// The fan start of a loop with the best worst triangle (normal along the loop's Newell normal,
// relative to its squared edge lengths), among fans whose diagonals never join two vertices of
// one face (such an edge could also be a diagonal in the neighbour across that face); -1 if none.
int best_fan_start(const float f[8], const uint8_t* loop, int n) {
  Vec3f p[12], normal{};
  for (int i = 0; i < n; ++i) p[i] = local_crossing(f, loop[i]);
  for (int i = 0; i < n; ++i) normal += cross(p[i], p[(i + 1) % n]);
  int best = -1;
  float best_quality = -kInfinity;
  for (int k = 0; k < n; ++k) {
    bool valid = true;
    for (int j = 2; j <= n - 2 && valid; ++j) valid = !kCube.same_face[loop[k]][loop[(k + j) % n]];
    if (!valid) continue;
    float quality = kInfinity;
    for (int j = 1; j <= n - 2; ++j) {
      const Vec3f a = p[k], b = p[(k + j) % n], c = p[(k + j + 1) % n];
      const float scale = dot(b - a, b - a) + dot(c - b, c - b) + dot(a - c, a - c);
      quality = std::min(quality, scale > 0 ? dot(cross(b - a, c - a), normal) / scale : 0.0f);
    }
    if (best < 0 || quality > best_quality) best = k, best_quality = quality;
  }
  return best;
}

// The cell's loops and their triangles (counter-clockwise seen from outside).
void triangulate_cell(const float f[8], CellSurface& out) {
  unsigned in = 0;
  for (int c = 0; c < 8; ++c) in |= unsigned(inside(f[c])) << c;
  if (in == 0 || in == 255) return;  // no crossings
  int next[12];
  for (int& e : next) e = -1;
  join_face_crossings(f, next);
  bool visited[12] = {};
  int used = 0;
  for (int e0 = 0; e0 < 12; ++e0) {
    if (next[e0] < 0 || visited[e0]) continue;
    const int begin = used;
    for (int e = e0; e >= 0 && !visited[e] && used < 12; e = next[e]) {
      assert(next[e] >= 0);
      visited[e] = true;
      out.loop_edges[used++] = uint8_t(e);
    }
    const uint8_t* loop = out.loop_edges + begin;
    const int n = used - begin;
    if (n < 3) continue;  // never: every crossing has one segment in and one out
    const int k = n == 3 ? 0 : best_fan_start(f, loop, n);
    if (k >= 0) {
      for (int j = 1; j <= n - 2; ++j) {
        uint8_t* t = out.triangles[out.triangle_count++];
        t[0] = loop[k], t[1] = loop[(k + j) % n], t[2] = loop[(k + j + 1) % n];
      }
    } else {
      const int centre = out.centre_count++;
      out.centre_begin[centre] = uint8_t(begin), out.centre_end[centre] = uint8_t(used);
      for (int j = 0; j < n; ++j) {
        uint8_t* t = out.triangles[out.triangle_count++];
        t[0] = uint8_t(12 + centre), t[1] = loop[j], t[2] = loop[(j + 1) % n];
      }
    }
  }
}

// The sampled grid: values at every grid point, x fastest.
struct GridValues {
  const SdfTree& tree;
  const MarchingCubesConfig& config;
  MarchingCubesGrid grid;
  std::vector<float> values;
  size_t stride_y = 0, stride_z = 0;

  size_t index(int i, int j, int k) const { return size_t(i) + stride_y * size_t(j) + stride_z * size_t(k); }
  float at(int i, int j, int k) const { return values[index(i, j, k)]; }
  Vec3f point(int i, int j, int k) const {
    return grid.origin + Vec3f{float(i), float(j), float(k)} * grid.cell;
  }
  // Bit a set when the edge from point (i, j, k) along axis a changes sign.
  unsigned crossings(int i, int j, int k) const {
    const bool in = inside(at(i, j, k));
    unsigned mask = 0;
    if (i < grid.n[0] && inside(at(i + 1, j, k)) != in) mask |= 1;
    if (j < grid.n[1] && inside(at(i, j + 1, k)) != in) mask |= 2;
    if (k < grid.n[2] && inside(at(i, j, k + 1)) != in) mask |= 4;
    return mask;
  }
  void corners(int i, int j, int k, float f[8]) const {
    for (int c = 0; c < 8; ++c) f[c] = at(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
  }
};

// The tree's analytic gradient direction; central differences where it vanishes; `fallback`
// where both do.
Vec3f unit_normal(const GridValues& g, Vec3f p, Vec3f fallback) {
  Vec3f n = sdf_gradient_normal(g.tree, p);
  if (!(is_finite(n) && dot(n, n) > 0.5f)) n = sdf_normal(g.tree, p, g.config.normal_step * g.grid.cell);
  return is_finite(n) && dot(n, n) > 0.5f ? n : fallback;
}

// The crossing on the edge from grid point (i, j, k) along axis a: linear interpolation, then
// Illinois-modified regula falsi steps that keep the sign change bracketed.
void edge_vertex(const GridValues& g, int i, int j, int k, int a, Vec3f& p, Vec3f& n) {
  const Vec3f p0 = g.point(i, j, k);
  Vec3f dir{};
  dir[a] = g.grid.cell;
  float fa = g.at(i, j, k), fb = g.at(i + (a == 0), j + (a == 1), k + (a == 2));
  const bool in0 = inside(fa);
  float ta = 0, tb = 1, t = crossing_fraction(fa, fb);
  int last = 0;  // the end replaced by the previous step: -1 = a, +1 = b
  for (int s = 0; s < g.config.refine_steps; ++s) {
    const float ft = sdf_eval(g.tree, p0 + dir * t);
    if (!std::isfinite(ft) || ft == 0) break;
    if (inside(ft) == in0) {
      ta = t, fa = ft;
      if (last < 0) fb *= 0.5f;  // b kept twice: halve its value (Illinois)
      last = -1;
    } else {
      tb = t, fb = ft;
      if (last > 0) fa *= 0.5f;
      last = 1;
    }
    const float next = ta + (tb - ta) * crossing_fraction(fa, fb);
    t = std::clamp(next, ta, tb);
  }
  p = p0 + dir * t;
  Vec3f outward{};
  outward[a] = in0 ? 1.0f : -1.0f;
  n = unit_normal(g, p, outward);
}

// The extra vertex of a loop: the mean of its crossings, moved by two Newton steps along the
// gradient towards f = 0 and kept inside the cell.
void centre_vertex(const GridValues& g, int i, int j, int k, const float f[8], const uint8_t* loop, int n,
                   Vec3f& p, Vec3f& normal) {
  Vec3f local{};
  for (int m = 0; m < n; ++m) local += local_crossing(f, loop[m]);
  local = local / float(n);
  const Vec3f lo = g.point(i, j, k), hi = g.point(i + 1, j + 1, k + 1);
  p = lo + local * g.grid.cell;
  const float h = g.config.normal_step * g.grid.cell;
  for (int s = 0; s < 2; ++s) {
    const float fp = sdf_eval(g.tree, p);
    const Vec3f dx{h, 0, 0}, dy{0, h, 0}, dz{0, 0, h};
    const Vec3f grad = Vec3f{sdf_eval(g.tree, p + dx) - sdf_eval(g.tree, p - dx),
                             sdf_eval(g.tree, p + dy) - sdf_eval(g.tree, p - dy),
                             sdf_eval(g.tree, p + dz) - sdf_eval(g.tree, p - dz)} /
                       (2 * h);
    const float g2 = dot(grad, grad);
    if (!(g2 > 0) || !std::isfinite(fp)) break;
    const Vec3f moved = p - grad * (fp / g2);
    if (!is_finite(moved)) break;
    p = min(max(moved, lo), hi);
  }
  normal = unit_normal(g, p, Vec3f{0, 0, 1});
}

// Running prefix counts of the crossings owned by the points of one grid row (fixed j, k):
// before = crossings of points 0 .. i-1; mask_i, mask_i1 = the crossings of points i, i + 1.
struct RowCursor {
  uint64_t base = 0;
  uint64_t before = 0;
  unsigned mask_i = 0, mask_i1 = 0;

  uint64_t vertex(int dx, int axis) const {
    const unsigned mask = dx ? mask_i1 : mask_i;
    const uint64_t skip = dx ? before + kBitCount[mask_i] : before;
    return base + skip + kBitCount[mask & ((1u << axis) - 1)];
  }
};

struct Offsets {
  std::vector<uint64_t> vertices, triangles;  // per row, exclusive prefix sums (size rows + 1)
};

size_t row_count(const MarchingCubesGrid& grid) {
  return size_t(grid.n[1] + 1) * size_t(grid.n[2] + 1);
}

// Grid points are sampled in blocks of kBlock^3. With skip_far_blocks, a block whose centre value
// exceeds L times (its half-diagonal + one cell) has the centre's sign at every point within a
// cell of it, so no crossing edge, four-crossing face or loop touches its points: they only need
// that sign, and take the centre's value. The mesh is the same as with every point evaluated.
constexpr int kBlock = 8;

void sample_block(GridValues& g, float lipschitz, const int lo[3], const int hi[3]) {
  if (lipschitz > 0) {
    Vec3f centre, half;
    for (int a = 0; a < 3; ++a) {
      centre[a] = g.grid.origin[a] + g.grid.cell * 0.5f * float(lo[a] + hi[a] - 1);
      half[a] = 0.5f * float(hi[a] - lo[a] - 1);
    }
    const float reach = lipschitz * g.grid.cell * (length(half) + 1);
    const float fc = sdf_eval(g.tree, centre);
    if (std::isfinite(fc) && std::abs(fc) > 1.01f * reach) {
      for (int k = lo[2]; k < hi[2]; ++k)
        for (int j = lo[1]; j < hi[1]; ++j)
          for (int i = lo[0]; i < hi[0]; ++i) g.values[g.index(i, j, k)] = fc;
      return;
    }
  }
  for (int k = lo[2]; k < hi[2]; ++k)
    for (int j = lo[1]; j < hi[1]; ++j)
      for (int i = lo[0]; i < hi[0]; ++i) g.values[g.index(i, j, k)] = sdf_eval(g.tree, g.point(i, j, k));
}

void sample_grid(GridValues& g) {
  g.values.resize(row_count(g.grid) * size_t(g.grid.n[0] + 1));
  int blocks[3];
  for (int a = 0; a < 3; ++a) blocks[a] = (g.grid.n[a] + 1 + kBlock - 1) / kBlock;
  const float l = g.config.skip_far_blocks ? sdf_lipschitz(g.tree) : 0.0f;
  const float lipschitz = std::isfinite(l) ? l : 0.0f;
  const size_t count = size_t(blocks[0]) * size_t(blocks[1]) * size_t(blocks[2]);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t b = r.begin(); b != r.end(); ++b) {
      const int index[3] = {int(b % size_t(blocks[0])), int(b / size_t(blocks[0]) % size_t(blocks[1])),
                            int(b / (size_t(blocks[0]) * size_t(blocks[1])))};
      int lo[3], hi[3];
      for (int a = 0; a < 3; ++a) {
        lo[a] = index[a] * kBlock;
        hi[a] = std::min(lo[a] + kBlock, g.grid.n[a] + 1);
      }
      sample_block(g, lipschitz, lo, hi);
    }
  });
}

// Per row: the vertices its points' edges and its cells' loop centres add, and its cells'
// triangles; then exclusive prefix sums.
Offsets count_rows(const GridValues& g) {
  const size_t rows = row_count(g.grid);
  Offsets o;
  o.vertices.assign(rows + 1, 0);
  o.triangles.assign(rows + 1, 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rows), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t row = r.begin(); row != r.end(); ++row) {
      const int j = int(row % size_t(g.grid.n[1] + 1)), k = int(row / size_t(g.grid.n[1] + 1));
      uint64_t vertices = 0, triangles = 0;
      for (int i = 0; i <= g.grid.n[0]; ++i) vertices += kBitCount[g.crossings(i, j, k)];
      if (j < g.grid.n[1] && k < g.grid.n[2])
        for (int i = 0; i < g.grid.n[0]; ++i) {
          float f[8];
          g.corners(i, j, k, f);
          CellSurface cell;
          triangulate_cell(f, cell);
          vertices += uint64_t(cell.centre_count);
          triangles += uint64_t(cell.triangle_count);
        }
      o.vertices[row] = vertices;
      o.triangles[row] = triangles;
    }
  });
  uint64_t v = 0, t = 0;
  for (size_t row = 0; row <= rows; ++row) {
    const uint64_t cv = o.vertices[row], ct = o.triangles[row];
    o.vertices[row] = v, o.triangles[row] = t;
    v += cv, t += ct;
  }
  return o;
}

// Writes row (j, k)'s edge vertices, then its cells' centre vertices and triangles.
void fill_row(const GridValues& g, const Offsets& o, int j, int k, IsosurfaceMesh& mesh) {
  const size_t ny1 = size_t(g.grid.n[1] + 1);
  const size_t row = size_t(j) + ny1 * size_t(k);
  uint64_t v = o.vertices[row];
  if (v == o.vertices[row + 1] && o.triangles[row] == o.triangles[row + 1]) return;  // far from the surface
  for (int i = 0; i <= g.grid.n[0]; ++i) {
    const unsigned mask = g.crossings(i, j, k);
    for (int a = 0; a < 3; ++a)
      if (mask & (1u << a)) edge_vertex(g, i, j, k, a, mesh.positions[v], mesh.normals[v]), ++v;
  }
  if (j >= g.grid.n[1] || k >= g.grid.n[2] || o.triangles[row] == o.triangles[row + 1]) return;
  RowCursor rows[4];  // rows (j + dy, k + dz) at index dy | dz << 1
  for (int r = 0; r < 4; ++r) {
    const int jj = j + (r & 1), kk = k + (r >> 1);
    rows[r].base = o.vertices[size_t(jj) + ny1 * size_t(kk)];
    rows[r].mask_i = g.crossings(0, jj, kk);
    rows[r].mask_i1 = g.crossings(1, jj, kk);
  }
  uint64_t t = o.triangles[row];
  for (int i = 0; i < g.grid.n[0]; ++i) {
    float f[8];
    g.corners(i, j, k, f);
    CellSurface cell;
    triangulate_cell(f, cell);
    uint64_t ids[16];
    for (int e = 0; e < 12 && cell.triangle_count > 0; ++e) {
      const int c = kCube.edge_corner[e][0];
      ids[e] = rows[((c >> 1) & 1) | ((c >> 2) << 1)].vertex(c & 1, e / 4);
    }
    for (int c = 0; c < cell.centre_count; ++c) {
      ids[12 + c] = v;
      centre_vertex(g, i, j, k, f, cell.loop_edges + cell.centre_begin[c],
                    cell.centre_end[c] - cell.centre_begin[c], mesh.positions[v], mesh.normals[v]);
      ++v;
    }
    for (int m = 0; m < cell.triangle_count; ++m, ++t)
      for (int q = 0; q < 3; ++q) mesh.indices[3 * t + q] = uint32_t(ids[cell.triangles[m][q]]);
    for (int r = 0; r < 4; ++r) {
      const int jj = j + (r & 1), kk = k + (r >> 1);
      rows[r].before += kBitCount[rows[r].mask_i];
      rows[r].mask_i = rows[r].mask_i1;
      rows[r].mask_i1 = i + 2 <= g.grid.n[0] ? g.crossings(i + 2, jj, kk) : 0;
    }
  }
  assert(v == o.vertices[row + 1] && t == o.triangles[row + 1]);
}

}  // namespace

MarchingCubesGrid marching_cubes_grid(const Bounds3f& box, int resolution,
                                      const MarchingCubesConfig& config) {
  if (resolution < 1 || resolution > kMaxMarchingCubesResolution)
    throw std::invalid_argument("marching cubes: resolution " + std::to_string(resolution) + " outside [1, " +
                                std::to_string(kMaxMarchingCubesResolution) + "]");
  if (config.padding < 0 || config.padding > 16)
    throw std::invalid_argument("marching cubes: padding outside [0, 16]");
  if (config.refine_steps < 0 || config.refine_steps > 16)
    throw std::invalid_argument("marching cubes: refine_steps outside [0, 16]");
  if (!(config.normal_step > 0 && config.normal_step <= 4))
    throw std::invalid_argument("marching cubes: normal_step outside (0, 4]");
  const Vec3f extent = box.extent();
  const float longest = max_component(extent);
  if (!is_finite(box.lo) || !is_finite(box.hi) || box.empty() || !(longest > 0) || !std::isfinite(longest))
    throw std::invalid_argument("marching cubes: the box is empty, flat or not finite");
  MarchingCubesGrid g;
  g.cell = longest / float(resolution);
  const Vec3f centre = box.center();
  for (int a = 0; a < 3; ++a) {
    const double cells = std::ceil(double(extent[a]) / double(longest) * resolution - 1e-6);
    g.n[a] = std::max(1, int(cells)) + 2 * config.padding;
    g.origin[a] = centre[a] - 0.5f * float(g.n[a]) * g.cell;
  }
  return g;
}

uint64_t mesh_bytes(uint64_t vertices, uint64_t triangles) {
  return vertices * 2 * sizeof(Vec3f) + triangles * 3 * sizeof(uint32_t);
}

uint64_t marching_cubes_work_bytes(const Bounds3f& box, int resolution, const MarchingCubesConfig& config) {
  const MarchingCubesGrid g = marching_cubes_grid(box, resolution, config);
  const uint64_t rows = uint64_t(g.n[1] + 1) * uint64_t(g.n[2] + 1);
  return rows * uint64_t(g.n[0] + 1) * sizeof(float) + 2 * (rows + 1) * sizeof(uint64_t);
}

uint64_t marching_cubes_bytes(const Bounds3f& box, int resolution, const MarchingCubesConfig& config) {
  const MarchingCubesGrid g = marching_cubes_grid(box, resolution, config);
  const uint64_t nx = uint64_t(g.n[0]), ny = uint64_t(g.n[1]), nz = uint64_t(g.n[2]);
  const uint64_t boundary_cells = 2 * (nx * ny + ny * nz + nx * nz);
  return marching_cubes_work_bytes(box, resolution, config) + 2 * boundary_cells * mesh_bytes(1, 2);
}

IsosurfaceMesh extract_isosurface(const SdfTree& tree, const Bounds3f& box, int resolution,
                                  const MarchingCubesConfig& config) {
  GridValues g{tree, config, marching_cubes_grid(box, resolution, config), {}, 0, 0};
  g.stride_y = size_t(g.grid.n[0] + 1);
  g.stride_z = g.stride_y * size_t(g.grid.n[1] + 1);
  // Phase 1: the SDF at every grid point.
  sample_grid(g);
  // Phase 2: vertices and triangles per row, and where each row's go.
  const Offsets o = count_rows(g);
  const uint64_t vertices = o.vertices.back(), triangles = o.triangles.back();
  if (vertices > UINT32_MAX)
    throw std::length_error("marching cubes: the mesh would have " + std::to_string(vertices) +
                            " vertices, more than 32-bit indices address");
  if (mesh_bytes(vertices, triangles) > config.max_output_bytes)
    throw std::length_error("marching cubes: the mesh needs " +
                            std::to_string(mesh_bytes(vertices, triangles)) + " bytes, more than the " +
                            std::to_string(config.max_output_bytes) + " allowed");
  // Phase 3: every row writes its own ranges.
  IsosurfaceMesh mesh;
  mesh.positions.resize(vertices);
  mesh.normals.resize(vertices);
  mesh.indices.resize(3 * triangles);
  const size_t rows = row_count(g.grid), ny1 = size_t(g.grid.n[1] + 1);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rows), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t row = r.begin(); row != r.end(); ++row) fill_row(g, o, int(row % ny1), int(row / ny1), mesh);
  });
  return mesh;
}

}  // namespace penumbra
