// The PENUMBRA_shapes extension: each node's extension object read by kind (analytic shapes;
// implicit shapes with their CSG trees: primitives, operators folded into binary nodes, noise
// displacement, node transforms, polyhedra named by mesh), the polyhedra's solids built from
// their meshes' triangles, then each shape placed by its node's world transform and instancing
// copies.
#include "io/gltf/shapes.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <span>

#include "io/gltf/accessors.h"
#include "io/gltf/json_reader.h"
#include "io/gltf/meshes.h"
#include "io/gltf/procedural.h"

namespace penumbra::gltf {

namespace {

using nlohmann::json;

// The schema's types: name, kind and the keys of that type beyond those every object has.
struct ShapeType {
  const char* name;
  ShapeKind kind;
  std::array<const char*, 3> keys;
};
constexpr ShapeType kShapeTypes[] = {
    {"sphere", ShapeKind::Sphere, {"radius"}},
    {"plane", ShapeKind::Plane, {"size"}},
    {"disk", ShapeKind::Disk, {"radius"}},
    {"box", ShapeKind::Box, {"size"}},
    {"capsule", ShapeKind::Capsule, {"radius", "height"}},
    {"implicit", ShapeKind::Implicit, {"csg", "maxSteps", "epsilon"}},
};
constexpr const char* kShapeCommonKeys[] = {"type", "material"};
constexpr const char* kShapeKeys[] = {"type",   "material", "radius",   "size",
                                      "height", "csg",      "maxSteps", "epsilon"};

struct CsgType {
  const char* name;
  SdfKind kind;
  std::array<const char*, 11> keys;
};
constexpr CsgType kCsgTypes[] = {
    {"sphere", SdfKind::Sphere, {"radius"}},
    {"box", SdfKind::Box, {"size"}},
    {"roundBox", SdfKind::RoundBox, {"size", "radius"}},
    {"capsule", SdfKind::Capsule, {"radius", "height"}},
    {"cylinder", SdfKind::Cylinder, {"radius", "height"}},
    {"cone", SdfKind::Cone, {"radius", "height"}},
    {"torus", SdfKind::Torus, {"majorRadius", "minorRadius"}},
    {"halfSpace", SdfKind::HalfSpace, {"normal", "offset"}},
    {"convexPolyhedron", SdfKind::ConvexPolyhedron, {"planes"}},
    {"polyhedron", SdfKind::Polyhedron, {"mesh"}},
    {"union", SdfKind::Union, {"children"}},
    {"intersection", SdfKind::Intersection, {"children"}},
    {"subtraction", SdfKind::Subtraction, {"children"}},
    {"complement", SdfKind::Complement, {"children"}},
    {"smoothUnion", SdfKind::SmoothUnion, {"children", "radius"}},
    {"smoothIntersection", SdfKind::SmoothIntersection, {"children", "radius"}},
    {"smoothSubtraction", SdfKind::SmoothSubtraction, {"children", "radius"}},
    {"displace",
     SdfKind::Displace,
     {"children", "amplitude", "frequency", "seed", "noise", "detail", "roughness", "lacunarity", "offset",
      "gain", "distortion"}},
};
constexpr const char* kCsgCommonKeys[] = {"type", "translation", "rotation", "scale", "matrix"};
constexpr const char* kCsgKeys[] = {"type",       "translation", "rotation",   "scale",       "matrix",
                                    "radius",     "size",        "height",     "majorRadius", "minorRadius",
                                    "normal",     "offset",      "planes",     "children",    "amplitude",
                                    "frequency",  "seed",        "noise",      "detail",      "roughness",
                                    "lacunarity", "gain",        "distortion", "mesh"};

// Limit of a displace node's |amplitude| and frequency.
constexpr float kMaxDisplacement = 1e6f;
// Largest Lipschitz bound a displace node may add (|amplitude| x frequency x the noise's gradient
// bound): sphere tracing steps by |f| / L, so beyond this a shape could not be traced.
constexpr float kMaxDisplacementLipschitz = 1e4f;

bool is_smooth(SdfKind kind) {
  return kind == SdfKind::SmoothUnion || kind == SdfKind::SmoothIntersection ||
         kind == SdfKind::SmoothSubtraction;
}

template <class Spec, size_t N>
const Spec* find_type(const Spec (&types)[N], const std::string& name) {
  for (const Spec& t : types)
    if (name == t.name) return &t;
  return nullptr;
}

template <class Spec, size_t N>
std::string type_names(const Spec (&types)[N]) {
  std::string s;
  for (const Spec& t : types) s += (s.empty() ? "" : ", ") + std::string(t.name);
  return s;
}

// Whether the inside of tree node `index` may be unbounded by the rules sdf_tree_bounds
// applies: half-spaces, open convex polyhedra and complements are; a union is if either part
// is, an intersection if both are, a subtraction if its first operand is.
bool may_be_unbounded(const SdfTree& tree, int index, int depth) {
  const SdfNode& n = tree.nodes[size_t(index)];
  if (depth > kMaxSdfDepth) return true;
  switch (n.kind) {
    case SdfKind::HalfSpace:
    case SdfKind::Complement:
      return true;
    case SdfKind::ConvexPolyhedron: {
      SdfTree alone;
      alone.nodes.push_back(n);
      alone.nodes[0].to_local = Affine3f{};
      alone.planes = tree.planes;
      alone.root = 0;
      return sdf_tree_bounds(alone).empty();
    }
    case SdfKind::Union:
    case SdfKind::SmoothUnion:
      return may_be_unbounded(tree, n.a, depth + 1) || may_be_unbounded(tree, n.b, depth + 1);
    case SdfKind::Intersection:
    case SdfKind::SmoothIntersection:
      return may_be_unbounded(tree, n.a, depth + 1) && may_be_unbounded(tree, n.b, depth + 1);
    case SdfKind::Subtraction:
    case SdfKind::SmoothSubtraction:
    case SdfKind::Displace:
      return may_be_unbounded(tree, n.a, depth + 1);
    default:
      return false;
  }
}

// The checks of a complete implicit shape: its inside bounded and not empty, its bounds and
// Lipschitz bound within the float range. `cw` is the JSON path of its csg member.
void check_implicit(const Shape& shape, const std::string& file, const std::string& cw) {
  const Bounds3f& b = shape.sdf_bounds;
  if (b.empty())
    throw InputError(
        file, cw,
        may_be_unbounded(shape.sdf, shape.sdf.root, 0)
            ? "the shape's inside is unbounded (intersect half-spaces and complements with a finite shape)"
            : "the shape's inside is empty (the parts it intersects do not overlap)");
  if (!is_finite(b.lo) || !is_finite(b.hi) || !(std::isfinite(shape.lipschitz) && shape.lipschitz > 0))
    throw InputError(file, cw, "the transforms scale the shape beyond the 32-bit float range");
}

// Reads extension objects into NodeShapes, one at a time; `m_tree` holds the CSG tree of the
// implicit shape being read, `m_pending` its polyhedron nodes.
class ShapeReader : public JsonReader {
 public:
  ShapeReader(const std::string& file, size_t materials, size_t meshes, MemoryBudget& budget)
      : JsonReader(file), m_file(file), m_materials(materials), m_meshes(meshes), m_budget(budget) {}
  NodeShape read(const json& ext, int node, const std::string& where);

 private:
  int material(const json& ext, const std::string& where) const;
  void analytic(const json& ext, const std::string& where, Shape& shape) const;
  Shape implicit(const json& ext, const std::string& where);
  int csg_node(const json& j, const std::string& where, int level);
  int csg_operator(const json& j, const std::string& where, SdfKind kind, int level);
  SdfNode csg_primitive(const json& j, const std::string& where, SdfKind kind);
  void csg_planes(const json& j, const std::string& where, SdfNode& node);
  int csg_displacement(const json& j, const std::string& where);
  int csg_polyhedron(const json& j, const std::string& where);
  Affine3f csg_transform(const json& j, const std::string& where) const;
  int add_node(const SdfNode& node, const std::string& where);

  const std::string& m_file;
  size_t m_materials, m_meshes;
  MemoryBudget& m_budget;
  SdfTree m_tree;
  std::vector<PendingPolyhedron> m_pending;
};

int ShapeReader::material(const json& ext, const std::string& where) const {
  const json* m = find(ext, "material");
  if (!m) return -1;
  const std::string mw = where + ".material";
  if (!m->is_number_integer()) fail(mw, "must be an integer material index (got " + shown(*m) + ")");
  if (!m->is_number_unsigned()) fail(mw, "index " + shown(*m) + " is negative");
  const uint64_t u = m->get<uint64_t>();
  if (u >= m_materials)
    fail(mw, "index " + std::to_string(u) + " out of range (" + std::to_string(m_materials) + " materials)");
  return int(u);
}

NodeShape ShapeReader::read(const json& ext, int node, const std::string& where) {
  if (!ext.is_object()) fail(where, "must be an object (got " + shown(ext) + ")");
  const json* type = find(ext, "type");
  if (!type) fail(where + ".type", "is required (one of " + type_names(kShapeTypes) + ")");
  if (!type->is_string()) fail(where + ".type", "must be a string (got " + shown(*type) + ")");
  const ShapeType* spec = find_type(kShapeTypes, type->get<std::string>());
  if (!spec)
    fail(where + ".type", "unknown shape type " + shown(*type) + " (known: " + type_names(kShapeTypes) + ")");
  check_keys(ext, where, "a \"" + std::string(spec->name) + "\" shape", kShapeCommonKeys, spec->keys,
             kShapeKeys);
  m_budget.charge(sizeof(NodeShape) + sizeof(SceneShape), where, "its shape needs");
  NodeShape out;
  out.node = node;
  out.material = material(ext, where);
  if (spec->kind == ShapeKind::Implicit) {
    out.shape = implicit(ext, where);
    if (!m_pending.empty()) out.csg = where + ".csg";
    out.polyhedra = std::move(m_pending);
    m_pending.clear();
  } else {
    out.shape.kind = spec->kind;
    analytic(ext, where, out.shape);
  }
  return out;
}

void ShapeReader::analytic(const json& ext, const std::string& where, Shape& shape) const {
  switch (shape.kind) {
    case ShapeKind::Sphere:
    case ShapeKind::Disk:
      shape.radius = number_or(ext, "radius", where, 1, Bound::Positive);
      break;
    case ShapeKind::Plane: {
      std::array<float, 2> size{2, 2};
      if (const json* v = find(ext, "size")) size = numbers<2>(*v, where + ".size", Bound::Positive);
      shape.half_size = {size[0] / 2, 0, size[1] / 2};
      break;
    }
    case ShapeKind::Box:
      shape.half_size = vec3_or(ext, "size", where, {1, 1, 1}, Bound::Positive) * 0.5f;
      break;
    case ShapeKind::Capsule:
      shape.radius = number_or(ext, "radius", where, 0.5f, Bound::Positive);
      shape.half_height = number_or(ext, "height", where, 1, Bound::NonNegative) / 2;
      break;
    case ShapeKind::Implicit:
    case ShapeKind::Segment:
    case ShapeKind::Splat:
      break;
  }
}

Shape ShapeReader::implicit(const json& ext, const std::string& where) {
  const std::string cw = where + ".csg";
  const json* csg = find(ext, "csg");
  if (!csg) fail(cw, "is required (the CSG tree of an implicit shape)");
  SphereTraceConfig trace;
  trace.max_steps = integer_or(ext, "maxSteps", where, 512, 1, 100000);
  if (const json* e = find(ext, "epsilon")) {
    trace.relative_epsilon = number(*e, where + ".epsilon", Bound::Positive);
    if (!(trace.relative_epsilon < 0.1f)) fail(where + ".epsilon", "must be < 0.1 (got " + shown(*e) + ")");
  }
  m_tree = SdfTree{};
  m_pending.clear();
  m_tree.root = csg_node(*csg, cw, 1);
  m_tree.nodes.shrink_to_fit();
  m_tree.planes.shrink_to_fit();
  m_tree.displacements.shrink_to_fit();
  m_tree.polyhedra.shrink_to_fit();
  if (!m_pending.empty()) {  // completed and checked once the polyhedra are built
    Shape shape;
    shape.kind = ShapeKind::Implicit;
    shape.sdf = std::move(m_tree);
    shape.trace = trace;
    return shape;
  }
  Shape shape = make_implicit_shape(std::move(m_tree), trace);
  check_implicit(shape, m_file, cw);
  return shape;
}

int ShapeReader::add_node(const SdfNode& node, const std::string& where) {
  if (m_tree.nodes.size() >= size_t(kMaxCsgNodes))
    fail(where, "the CSG tree has more than " + std::to_string(kMaxCsgNodes) +
                    " nodes (counting the binary nodes operators with more than 2 children fold into)");
  m_budget.charge(sizeof(SdfNode), where, "its CSG node needs");
  m_tree.nodes.push_back(node);
  return int(m_tree.nodes.size()) - 1;
}

// A CSG node at `level` (the root is level 1): its type, keys and transform, then its fields
// or children. The level is checked before anything below is read, so recursion stays within
// kMaxSdfDepth frames whatever the file's nesting.
int ShapeReader::csg_node(const json& j, const std::string& where, int level) {
  if (level > kMaxSdfDepth)
    fail(where, "the CSG tree is deeper than " + std::to_string(kMaxSdfDepth) +
                    " levels (an operator with n children counts n - 1 levels)");
  if (!j.is_object()) fail(where, "must be a CSG node object (got " + shown(j) + ")");
  const json* type = find(j, "type");
  if (!type) fail(where + ".type", "is required (one of " + type_names(kCsgTypes) + ")");
  if (!type->is_string()) fail(where + ".type", "must be a string (got " + shown(*type) + ")");
  const CsgType* spec = find_type(kCsgTypes, type->get<std::string>());
  if (!spec)
    fail(where + ".type",
         "unknown CSG node type " + shown(*type) + " (known: " + type_names(kCsgTypes) + ")");
  check_keys(j, where, "a \"" + std::string(spec->name) + "\" CSG node", kCsgCommonKeys, spec->keys,
             kCsgKeys);
  const Affine3f to_local = csg_transform(j, where);
  const int index = is_operator(spec->kind) ? csg_operator(j, where, spec->kind, level)
                                            : add_node(csg_primitive(j, where, spec->kind), where);
  m_tree.nodes[size_t(index)].to_local = to_local;
  return index;
}

// An operator's children folded left to right into binary nodes, ((c0 op c1) op c2) ..., the
// last one at `level`; returns it. Subtraction so takes each later child from the first.
int ShapeReader::csg_operator(const json& j, const std::string& where, SdfKind kind, int level) {
  const std::string cw = where + ".children";
  const json* children = find(j, "children");
  if (!children) fail(cw, "is required");
  if (!children->is_array()) fail(cw, "must be an array of CSG nodes (got " + shown(*children) + ")");
  const size_t n = children->size();
  if (is_unary(kind) && n != 1) fail(cw, "must hold exactly 1 CSG node (got " + std::to_string(n) + ")");
  if (!is_unary(kind) && n < 2) fail(cw, "must hold at least 2 CSG nodes (got " + std::to_string(n) + ")");
  if (uint64_t(level) + n - 1 > uint64_t(kMaxSdfDepth))
    fail(cw, std::to_string(n) + " children fold into " + std::to_string(n - 1) +
                 " nested binary nodes: the CSG tree would be deeper than " + std::to_string(kMaxSdfDepth) +
                 " levels (nest balanced operators instead)");
  SdfNode op;
  op.kind = kind;
  if (is_smooth(kind)) {
    const json* r = find(j, "radius");
    if (!r) fail(where + ".radius", "is required (the blend radius)");
    op.radius = number(*r, where + ".radius", Bound::Positive);
  }
  if (kind == SdfKind::Displace) op.displacement = csg_displacement(j, where);
  if (is_unary(kind)) {
    op.a = csg_node((*children)[0], idx(cw.c_str(), 0), level + 1);
    return add_node(op, where);
  }
  op.a = csg_node((*children)[0], idx(cw.c_str(), 0), level + int(n) - 1);
  for (size_t k = 1; k < n; ++k) {
    op.b = csg_node((*children)[k], idx(cw.c_str(), k), level + int(n - k));
    op.a = add_node(op, where);
  }
  return op.a;
}

SdfNode ShapeReader::csg_primitive(const json& j, const std::string& where, SdfKind kind) {
  SdfNode n;
  n.kind = kind;
  switch (kind) {
    case SdfKind::Sphere: {
      const float r = number_or(j, "radius", where, 1, Bound::Positive);
      n.size = {r, r, r};
      break;
    }
    case SdfKind::Box:
      n.size = vec3_or(j, "size", where, {1, 1, 1}, Bound::Positive) * 0.5f;
      break;
    case SdfKind::RoundBox: {
      n.size = vec3_or(j, "size", where, {1, 1, 1}, Bound::Positive) * 0.5f;
      const json* r = find(j, "radius");
      if (!r) fail(where + ".radius", "is required (the edge radius)");
      n.radius = number(*r, where + ".radius", Bound::Positive);
      const float smallest = std::min({n.size.x, n.size.y, n.size.z});
      if (n.radius > smallest)
        fail(where + ".radius",
             "must be <= the smallest half extent " + format_number(smallest) + " (got " + shown(*r) + ")");
      break;
    }
    case SdfKind::Capsule:
    case SdfKind::Cylinder:
    case SdfKind::Cone:
      n.radius = number_or(j, "radius", where, 0.5f, Bound::Positive);
      n.size = {
          n.radius,
          number_or(j, "height", where, 1, kind == SdfKind::Capsule ? Bound::NonNegative : Bound::Positive) /
              2,
          n.radius};
      break;
    case SdfKind::Torus: {
      n.size.x = number_or(j, "majorRadius", where, 1, Bound::Positive);
      n.radius = number_or(j, "minorRadius", where, 0.25f, Bound::Positive);
      if (!(n.radius < n.size.x))
        fail(where + ".minorRadius",
             "must be < majorRadius " + format_number(n.size.x) + " (got " + format_number(n.radius) + ")");
      break;
    }
    case SdfKind::HalfSpace: {
      const Vec3f v = vec3_or(j, "normal", where, {0, 1, 0}, Bound::Any);
      const double len = std::sqrt(double(v.x) * v.x + double(v.y) * v.y + double(v.z) * v.z);
      if (!(len > 0)) fail(where + ".normal", "must be non-zero");
      n.normal = {float(v.x / len), float(v.y / len), float(v.z / len)};
      n.offset = number_or(j, "offset", where, 0, Bound::Any);
      break;
    }
    case SdfKind::ConvexPolyhedron:
      csg_planes(j, where, n);
      break;
    case SdfKind::Polyhedron:
      n.polyhedron = csg_polyhedron(j, where);
      break;
    default:
      break;
  }
  return n;
}

// A polyhedron node's mesh index, checked against the meshes; its (empty) entry in
// SdfTree::polyhedra, filled by place_shapes. Returns the entry's index.
int ShapeReader::csg_polyhedron(const json& j, const std::string& where) {
  const std::string mw = where + ".mesh";
  const json* m = find(j, "mesh");
  if (!m) fail(mw, "is required (the index of the glTF mesh whose triangles bound the solid)");
  if (!m->is_number_integer()) fail(mw, "must be an integer mesh index (got " + shown(*m) + ")");
  if (!m->is_number_unsigned()) fail(mw, "index " + shown(*m) + " is negative");
  const uint64_t u = m->get<uint64_t>();
  if (u >= m_meshes)
    fail(mw, "mesh " + std::to_string(u) + " out of range (" + std::to_string(m_meshes) + " meshes)");
  m_budget.charge(sizeof(SolidMesh) + sizeof(PendingPolyhedron) + mw.size(), where, "its polyhedron needs");
  m_tree.polyhedra.emplace_back();
  const int index = int(m_tree.polyhedra.size()) - 1;
  m_pending.push_back({index, int(u), mw});
  return index;
}

void ShapeReader::csg_planes(const json& j, const std::string& where, SdfNode& node) {
  const std::string pw = where + ".planes";
  const json* planes = find(j, "planes");
  if (!planes) fail(pw, "is required");
  if (!planes->is_array())
    fail(pw, "must be an array of [nx, ny, nz, d] planes (got " + shown(*planes) + ")");
  const size_t n = planes->size();
  if (n < 4 || n > kMaxConvexPlanes)
    fail(pw,
         "must hold 4 to " + std::to_string(kMaxConvexPlanes) + " planes (got " + std::to_string(n) + ")");
  m_budget.charge(n * sizeof(Vec4f), pw, std::to_string(n) + " planes need");
  node.first_plane = int(m_tree.planes.size());
  node.plane_count = int(n);
  for (size_t i = 0; i < n; ++i) {
    const std::string w = idx(pw.c_str(), i);
    const auto p = numbers<4>((*planes)[i], w, Bound::Any);
    const double len = std::sqrt(double(p[0]) * p[0] + double(p[1]) * p[1] + double(p[2]) * p[2]);
    if (!(len > 0)) fail(w, "the normal (the first three values) must be non-zero");
    const Vec4f unit{float(p[0] / len), float(p[1] / len), float(p[2] / len), float(p[3] / len)};
    if (!std::isfinite(unit.w)) fail(w, "d over the normal's length is beyond the 32-bit float range");
    m_tree.planes.push_back(unit);
  }
}

// A displace node's noise (amplitude, frequency, seed, fractal parameters), stored in the tree;
// returns its index in SdfTree::displacements.
int ShapeReader::csg_displacement(const json& j, const std::string& where) {
  SdfDisplacement d;
  if (!find(j, "amplitude")) fail(where + ".amplitude", "is required (the noise's largest displacement)");
  d.amplitude = number_in(j, "amplitude", where, 0, -kMaxDisplacement, kMaxDisplacement);
  d.frequency = number_or(j, "frequency", where, 1, Bound::Positive);
  if (!(d.frequency <= kMaxDisplacement))
    fail(where + ".frequency",
         "must be <= " + format_number(kMaxDisplacement) + " (got " + format_number(d.frequency) + ")");
  const uint32_t seed = uint32_or(j, "seed", where, 0);
  d.params = read_fractal_params(*this, j, where, "noise");
  const double added = double(std::abs(d.amplitude)) * d.frequency * fractal_gradient_bound(d.params);
  if (!(added <= kMaxDisplacementLipschitz))
    fail(where,
         "the noise raises the Lipschitz bound by " + format_number(added) + " (at most " +
             format_number(kMaxDisplacementLipschitz) +
             ": sphere tracing steps by |f| / L); lower amplitude, frequency, detail, lacunarity or gain");
  m_budget.charge(sizeof(SdfDisplacement), where, "its noise table needs");
  d.table = make_perlin_table(seed);
  m_tree.displacements.push_back(d);
  return int(m_tree.displacements.size()) - 1;
}

// The node's glTF-style transform (matrix, or translation x rotation x scale) placing its frame
// in the parent's; returns its inverse, SdfNode::to_local.
Affine3f ShapeReader::csg_transform(const json& j, const std::string& where) const {
  Transform t;
  const bool matrix = matrix_or(j, "matrix", where, t);
  if (!matrix) {
    std::array<double, 3> tr{0, 0, 0}, sc{1, 1, 1};
    Quat q;
    if (const json* v = find(j, "translation")) {
      const auto a = numbers<3>(*v, where + ".translation", Bound::Any);
      tr = {a[0], a[1], a[2]};
    }
    if (const json* v = find(j, "rotation")) {
      const auto a = numbers<4>(*v, where + ".rotation", Bound::Any);
      q = {a[0], a[1], a[2], a[3]};
      const double len = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
      if (!(std::fabs(len - 1) <= 1e-3))
        fail(where + ".rotation", "must be a unit quaternion (length " + format_number(len) + ")");
    }
    if (const json* v = find(j, "scale")) {
      const auto a = numbers<3>(*v, where + ".scale", Bound::NonZero);
      sc = {a[0], a[1], a[2]};
    }
    t = compose_trs(tr, q, sc);
  }
  Transform inv;
  Affine3f to_local, back;
  if (!inverse(t, inv) || !is_finite(inv) || !inverse(to_local = to_affine(inv), back))
    fail(matrix ? where + ".matrix" : where,
         "the transform is singular or its inverse is beyond the 32-bit float range");
  return to_local;
}

// Bytes building a solid holds beyond what it keeps, per triangle (the welded copy, the edge list
// for the closedness check, areas, the BVH order and centroids) and per node-budget unit (a node
// and, at worst, a polygon fragment with 16 vertices of the splitting pool).
constexpr uint64_t kSolidBuildBytesPerTriangle = 128;
constexpr uint64_t kSolidBuildBytesPerNode = sizeof(SolidBspNode) + 64 + 16 * 24;

const char* mode_name(int mode) {
  static const char* const kNames[] = {"POINTS",    "LINES",          "LINE_LOOP",   "LINE_STRIP",
                                       "TRIANGLES", "TRIANGLE_STRIP", "TRIANGLE_FAN"};
  return mode >= 0 && mode <= 6 ? kNames[mode] : "invalid";
}

// The sizes of glTF mesh `mesh`'s primitives read from their accessors' counts, before any is
// decoded: each must be TRIANGLES with a POSITION attribute. `where` (the polyhedron's "mesh"
// member) and `name` ("mesh 3") name errors.
struct MeshSizes {
  uint64_t vertices = 0, indices = 0;
};
MeshSizes mesh_sizes(const GltfContext& ctx, int mesh, const std::string& where, const std::string& name) {
  const auto& primitives = ctx.model.meshes[size_t(mesh)].primitives;
  if (primitives.empty()) ctx.fail(where, name + " has no primitives");
  const auto count = [&](int accessor) {
    return accessor >= 0 && size_t(accessor) < ctx.model.accessors.size()
               ? uint64_t(ctx.model.accessors[size_t(accessor)].count)
               : uint64_t(0);
  };
  MeshSizes sizes;
  for (size_t pi = 0; pi < primitives.size(); ++pi) {
    const auto& prim = primitives[pi];
    const std::string pn = name + "'s " + idx("primitives", pi);
    if (prim.mode != TINYGLTF_MODE_TRIANGLES)
      ctx.fail(where, pn + " has mode " + std::to_string(prim.mode) + " (" + mode_name(prim.mode) +
                          "); a polyhedron needs TRIANGLES (mode 4) primitives");
    const auto pos = prim.attributes.find("POSITION");
    if (pos == prim.attributes.end()) ctx.fail(where, pn + " has no POSITION attribute");
    const uint64_t nv = count(pos->second), ni = prim.indices >= 0 ? count(prim.indices) : nv;
    if (ni % 3) ctx.fail(where, pn + " has " + std::to_string(ni) + " indices, not a multiple of 3");
    sizes.vertices += nv;
    sizes.indices += ni;
    if (sizes.indices / 3 > kMaxPolyhedronTriangles)
      ctx.fail(where, name + " has more than " + std::to_string(kMaxPolyhedronTriangles) +
                          " triangles (the most a polyhedron may have)");
    if (sizes.vertices >= 0xffffffffu) ctx.fail(where, name + " has too many vertices");
  }
  return sizes;
}

// The triangles of glTF mesh `mesh`'s primitives (checked by mesh_sizes), vertices numbered
// across the primitives in order.
void mesh_triangles(const GltfContext& ctx, int mesh, const std::string& where, const std::string& name,
                    std::vector<Vec3f>& positions, std::vector<uint32_t>& indices) {
  const auto& used = ctx.model.extensionsUsed;
  const bool quantized = std::find(used.begin(), used.end(), "KHR_mesh_quantization") != used.end();
  const auto& primitives = ctx.model.meshes[size_t(mesh)].primitives;
  for (size_t pi = 0; pi < primitives.size(); ++pi) {
    const auto& prim = primitives[pi];
    const std::string pw = idx("meshes", size_t(mesh)) + "." + idx("primitives", pi);
    const int pos = prim.attributes.at("POSITION");
    const std::vector<double> xyz =
        quantized ? read_accessor(ctx, pos, pw + ".attributes.POSITION", {TINYGLTF_TYPE_VEC3},
                                  {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE,
                                   TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_SHORT,
                                   TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                                  true, true)
                  : read_accessor(ctx, pos, pw + ".attributes.POSITION", {TINYGLTF_TYPE_VEC3},
                                  {TINYGLTF_COMPONENT_TYPE_FLOAT}, false);
    const size_t nv = xyz.size() / 3, base = positions.size();
    std::vector<uint32_t> local;
    if (prim.indices >= 0) {
      local = read_indices(ctx, prim.indices, pw + ".indices");
    } else {
      local.resize(nv);
      for (size_t i = 0; i < nv; ++i) local[i] = uint32_t(i);
    }
    for (size_t i = 0; i < nv; ++i)
      positions.push_back({float(xyz[3 * i]), float(xyz[3 * i + 1]), float(xyz[3 * i + 2])});
    for (const uint32_t i : local) {
      if (i >= nv)
        ctx.fail(where, name + "'s " + idx("primitives", pi) + " has index " + std::to_string(i) +
                            " >= its vertex count " + std::to_string(nv));
      indices.push_back(uint32_t(base) + i);
    }
  }
}

// The solid of glTF mesh `mesh` for the polyhedron node whose "mesh" member is `where`. What
// decoding, the triangles and the build hold is charged first, from the accessors' counts
// (decoding then charges its part again, in the room given back for it), then exchanged for
// what the solid keeps.
SolidMesh build_polyhedron(const GltfContext& ctx, int mesh, const std::string& where) {
  const std::string name = "mesh " + std::to_string(mesh);
  const uint64_t before = ctx.budget.used();
  const MeshSizes sizes = mesh_sizes(ctx, mesh, where, name);
  const uint64_t triangles = sizes.indices / 3;
  const uint64_t decoding = sizes.vertices * 3 * 8 + sizes.indices * 8;
  ctx.charge(decoding + sizes.vertices * sizeof(Vec3f) + sizes.indices * sizeof(uint32_t) +
                 triangles * kSolidBuildBytesPerTriangle,
             where, name + "'s " + std::to_string(triangles) + " triangles need");
  ctx.budget.release(decoding);
  std::vector<Vec3f> positions;
  std::vector<uint32_t> indices;
  positions.reserve(size_t(sizes.vertices));
  indices.reserve(size_t(sizes.indices));
  mesh_triangles(ctx, mesh, where, name, positions, indices);
  SolidBspConfig config;
  config.max_classifications = kMaxPolyhedronClassifications;
  const uint64_t automatic = 8 * triangles + 1024;
  const uint64_t affordable = (ctx.budget.limit() - ctx.budget.used()) / kSolidBuildBytesPerNode;
  const bool by_memory = affordable < automatic;
  config.max_nodes = std::max<uint64_t>(1, std::min(automatic, affordable));
  SolidMesh solid;
  try {
    solid = build_solid_mesh(positions, indices, config);
  } catch (const SolidMeshError& e) {
    if (e.over_budget() && by_memory && e.reason().find("max_classifications") == std::string::npos)
      ctx.fail(where, name + "'s solid BSP needs more than the " + format_bytes(ctx.budget.limit()) +
                          " budget allows with the rest of the scene (" + e.reason() + ")");
    ctx.fail(where, name + " " + e.reason());
  }
  ctx.budget.release(ctx.budget.used() - before);
  ctx.charge(solid_mesh_bytes(solid), where, name + "'s solid needs");
  if (solid.bsp.flipped)
    ctx.warn(where,
             name + " winds inwards (its signed volume is negative); its triangles are taken reversed");
  return solid;
}

// Builds the polyhedra of every shape that has some (a mesh once, then copied), and completes and
// checks those shapes.
void build_polyhedra(const GltfContext& ctx, std::vector<NodeShape>& shapes) {
  std::map<int, std::pair<size_t, int>> built;  // mesh -> (shape, polyhedron) holding its solid
  for (size_t si = 0; si < shapes.size(); ++si) {
    NodeShape& s = shapes[si];
    if (s.polyhedra.empty()) continue;
    for (const PendingPolyhedron& p : s.polyhedra) {
      SolidMesh& slot = s.shape.sdf.polyhedra[size_t(p.index)];
      const auto it = built.find(p.mesh);
      if (it == built.end()) {
        slot = build_polyhedron(ctx, p.mesh, p.where);
        built[p.mesh] = {si, p.index};
      } else {
        slot = shapes[it->second.first].shape.sdf.polyhedra[size_t(it->second.second)];
        ctx.charge(solid_mesh_bytes(slot), p.where, "mesh " + std::to_string(p.mesh) + "'s solid needs");
      }
    }
    s.polyhedra.clear();
    s.shape = make_implicit_shape(std::move(s.shape.sdf), s.shape.trace);
    check_implicit(s.shape, ctx.file, s.csg);
  }
}

// One shape placed by its node: the SceneShape, then an instance per placement (never marked
// the identity on a moving node). Returns how many placements were left out.
uint64_t place_shape(const GltfContext& ctx, NodeShape& from, const Transform& world, bool moving) {
  const int node = from.node;
  const auto& gnode = ctx.model.nodes[size_t(node)];
  const std::string where = idx("nodes", size_t(node));
  const bool per_copy = gnode.extensions.count("EXT_mesh_gpu_instancing") > 0;
  const uint64_t count = declared_placements(ctx, node);
  uint64_t bytes = 0;
  if (!mul_ok(count, sizeof(Transform) + sizeof(Instance) + kAccelBytesPerInstance, bytes))
    bytes = UINT64_MAX;
  ctx.charge(bytes, per_copy ? where + ".extensions.EXT_mesh_gpu_instancing" : where,
             std::to_string(count) + (count == 1 ? " instance needs" : " instances need"));
  const std::vector<Transform> placements = placements_of(ctx, node, world);
  const int index = int(ctx.out.scene.shapes.size());
  SceneShape& shape = ctx.out.scene.shapes.emplace_back();
  shape.name = gnode.name.empty() ? where : gnode.name;
  shape.shape = std::move(from.shape);
  shape.material = from.material;
  shape.node = node;
  const Bounds3f object = shape_bounds(shape.shape);
  uint64_t skipped = 0;
  for (size_t k = 0; k < placements.size(); ++k) {
    const Affine3f to_world = to_affine(placements[k]);
    Affine3f to_object;
    const Bounds3f b = transform_bounds(to_world, object);
    const bool usable = inverse(to_world, to_object) && is_finite(b.lo) && is_finite(b.hi) &&
                        std::max(max_component(abs(b.lo)), max_component(abs(b.hi))) <= 1e18f;
    if (!usable) {
      ++skipped;
      continue;
    }
    Instance inst = make_shape_instance(index, to_world, node);
    inst.copy = per_copy ? int(k) : -1;
    if (moving) inst.identity = false;
    ctx.out.scene.instances.push_back(inst);
  }
  if (skipped == 1 && placements.size() == 1)
    ctx.warn(where, "singular, non-finite or huge transform; shape skipped");
  else if (skipped > 0)
    ctx.warn(where + ".extensions.EXT_mesh_gpu_instancing",
             std::to_string(skipped) + " of " + std::to_string(placements.size()) +
                 " instances have a singular, non-finite or huge transform; skipped");
  return skipped;
}

}  // namespace

std::vector<NodeShape> read_node_shapes(const json& doc, const std::string& file, MemoryBudget& budget) {
  std::vector<NodeShape> out;
  const auto nodes = doc.find("nodes");
  if (nodes == doc.end() || !nodes->is_array()) return out;
  const auto materials = doc.find("materials");
  const auto meshes = doc.find("meshes");
  ShapeReader reader(file, materials != doc.end() && materials->is_array() ? materials->size() : 0,
                     meshes != doc.end() && meshes->is_array() ? meshes->size() : 0, budget);
  for (size_t i = 0; i < nodes->size(); ++i) {
    const json& node = (*nodes)[i];
    const auto extensions = node.find("extensions");
    if (extensions == node.end() || !extensions->is_object()) continue;
    const auto ext = extensions->find(kShapesExtension);
    if (ext == extensions->end()) continue;
    out.push_back(reader.read(*ext, int(i), idx("nodes", i) + ".extensions." + kShapesExtension));
  }
  return out;
}

void place_shapes(const GltfContext& ctx, std::vector<NodeShape>& shapes, NodeTransforms& nodes,
                  const std::vector<int>& shape_nodes) {
  build_polyhedra(ctx, shapes);
  for (const int node : shape_nodes) {
    const auto it = std::lower_bound(shapes.begin(), shapes.end(), node,
                                     [](const NodeShape& s, int n) { return s.node < n; });
    if (it == shapes.end() || it->node != node) continue;
    const uint64_t skipped = place_shape(ctx, *it, nodes.world[size_t(node)], is_moving(nodes, node));
    if (is_moving(nodes, node)) nodes.moving_skipped += skipped;
  }
}

}  // namespace penumbra::gltf
