// The uniform SAH of penumbra-bench (benchmarks/sah.h): the terms of BVH build trees, and how
// each structure's terms are obtained.
#include "benchmarks/sah.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "renderer/accel/bvh_wide.h"
#include "renderer/accel/common.h"

namespace penumbra::bench {

namespace {

/// Sums the terms over a build tree in the order accel/bvh.cpp sums its own SAH.
struct BvhTermWalker {
  double root_area = 0;
  int width = 2, block = 1;
  SahTerms terms;

  double rel(const Bounds3f& b) const { return root_area > 0 ? double(surface_area(b)) / root_area : 1.0; }
  double charge(uint32_t n) const {
    return double(block <= 1 ? n : (n + uint32_t(block) - 1) / uint32_t(block));
  }

  void binary(const BvhBuildNode& b) {
    if (!b.child[0]) {
      terms.leaf_area += rel(b.box) * charge(b.count);
      return;
    }
    terms.interior_area += rel(b.box);
    binary(*b.child[0]);
    binary(*b.child[1]);
  }

  void wide(const BvhBuildNode& b) {
    terms.interior_area += rel(b.box);
    const BvhBuildNode* kids[8];
    int n = 0;
    if (!b.child[0]) {
      kids[n++] = &b;
    } else {
      kids[n++] = b.child[0].get();
      kids[n++] = b.child[1].get();
    }
    while (n < width) {
      int open = -1;
      float area = -1;
      for (int i = 0; i < n; ++i)
        if (kids[i]->child[0] && surface_area(kids[i]->box) > area) {
          area = surface_area(kids[i]->box);
          open = i;
        }
      if (open < 0) break;
      const BvhBuildNode* o = kids[open];
      kids[open] = o->child[0].get();
      kids[n++] = o->child[1].get();
    }
    for (int i = 0; i < n; ++i) {
      if (kids[i]->child[0])
        wide(*kids[i]);
      else
        terms.leaf_area += rel(kids[i]->box) * charge(kids[i]->count);
    }
  }
};

bool close(double a, double b, double rel) {
  return std::fabs(a - b) <= rel * std::max({std::fabs(a), std::fabs(b), 1e-300});
}

/// The views of the single-level build make_accelerator makes when every instance is the identity
/// (the instances' meshes in instance order); false for a two-level build.
bool single_level_views(std::span<const GeometryView> views, std::span<const InstanceView> instances,
                        std::vector<GeometryView>& out) {
  for (const auto& i : instances) {
    if (!is_identity(i.to_world) || i.mesh >= views.size()) return false;
    out.push_back(views[i.mesh]);
  }
  return true;
}

/// The width `stats` reports in its config ("width N, ..."), else the builder's default.
int bvh_width(const AccelStats& stats, const BvhConfig& config) {
  int w = 0;
  if (std::sscanf(stats.config.c_str(), "width %d", &w) == 1 && (w == 2 || w == 4 || w == 8)) return w;
  return config.width != 0 ? config.width : (cpu_has_avx2() ? 8 : 4);
}

std::optional<SahTerms> bvh_terms(std::span<const GeometryView> views, const BvhConfig& config,
                                  const AccelStats& stats, std::string& note) {
  std::vector<Shape> shapes;
  const std::vector<PrimitiveRecord> prims = gather_primitives(views, shapes);
  if (prims.empty()) {
    note = "no primitives";
    return std::nullopt;
  }
  std::vector<BvhBuildRef> refs(prims.size());
  for (size_t i = 0; i < prims.size(); ++i) refs[i] = {primitive_bounds(prims[i]), uint32_t(i)};
  const ReferenceClipper clip = [&](const BvhBuildRef& ref, int axis, float pos, Bounds3f& l, Bounds3f& r) {
    const PrimitiveRecord& t = prims[ref.index];
    if (is_shape(t)) return split_box_bounds(ref.box(), axis, pos, l, r);
    const Vec3f v[3] = {t.a, t.b, t.c};
    split_triangle_bounds(v, ref.box(), axis, pos, l, r);
  };
  const int width = bvh_width(stats, config), block = width == 2 ? 1 : 4;
  const auto root = build_bvh_tree(refs, config, block, &clip);
  const SahTerms own = bvh_sah_terms(*root, width, block);
  const double own_cost =
      own.interior_area * double(config.traversal_cost) + own.leaf_area * double(config.intersection_cost);
  if (!close(own_cost, stats.sah_cost, 1e-6)) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "the rebuilt tree's SAH %.9g differs from the builder's %.9g", own_cost,
                  stats.sah_cost);
    note = buf;
    return std::nullopt;
  }
  return bvh_sah_terms(*root, width, 1);
}

}  // namespace

double sah_cost(const SahTerms& t, const SahConstants& c) {
  return c.traversal * t.interior_area + c.intersection * t.leaf_area;
}

SahTerms bvh_sah_terms(const BvhBuildNode& root, int width, int block) {
  BvhTermWalker w;
  w.root_area = surface_area(root.box);
  w.width = std::clamp(width, 2, 8);
  w.block = std::max(block, 1);
  if (w.width == 2)
    w.binary(root);
  else
    w.wide(root);
  return w.terms;
}

StructureSah measure_structure_sah(std::string_view name, std::span<const GeometryView> views,
                                   std::span<const InstanceView> instances, const AccelConfig& config,
                                   const Accelerator& built, const SahConstants& constants) {
  StructureSah out;
  if (name == "embree") {
    out.note = "Embree does not expose its nodes";
    return out;
  }
  const bool reports_terms = name == "kdtree" || name == "octree" || name == "bsp";
  if (name != "bvh" && !reports_terms) {
    out.note = std::string(name) + " is not a tree";
    return out;
  }
  if (std::any_of(views.begin(), views.end(), [](const GeometryView& v) { return v.deforms(); })) {
    out.note = "deforming meshes: linear bounds over time, no still SAH";
    return out;
  }
  std::vector<GeometryView> level;
  if (!single_level_views(views, instances, level)) {
    out.note = "two-level build (placed instances): the top level is not visible";
    return out;
  }
  if (reports_terms) {
    const AccelStats st = built.stats();
    if (st.sah_node_area + st.sah_leaf_area > 0)
      out.terms = SahTerms{st.sah_node_area, st.sah_leaf_area};
    else
      out.note = "the " + std::string(name) + " reports no SAH terms";
    if (out.terms) out.cost = sah_cost(*out.terms, constants);
    return out;
  }
  out.terms = bvh_terms(level, config.bvh, built.stats(), out.note);
  if (out.terms) out.cost = sah_cost(*out.terms, constants);
  return out;
}

}  // namespace penumbra::bench
