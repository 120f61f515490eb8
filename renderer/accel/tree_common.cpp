// The non-template parts of the tree skeleton (accel/tree_common.h): the automatic depth limit,
// the size checks and the SAH trees' configuration text.
#include "renderer/accel/tree_common.h"

#include <cmath>
#include <stdexcept>

namespace penumbra {

int tree_max_depth(int configured, size_t primitives, int cap) {
  if (configured > 0) return configured;
  return std::min(cap, int(std::lround(8 + 1.3 * std::log2(std::max<size_t>(primitives, 1)))));
}

void check_primitive_count(const TreeFormat& format, size_t count) {
  if (count > format.max_index)
    throw std::runtime_error(std::string(format.name) + ": too many primitives (max " +
                             format.max_index_text + ")");
}

void check_tree_size(const TreeFormat& format, size_t nodes, size_t references) {
  if (nodes > format.max_index || references > format.max_index)
    throw std::runtime_error(std::string(format.name) + ": tree too large (more than " +
                             format.max_index_text + " nodes or references)");
}

std::string sah_tree_config(float traversal_cost, float intersection_cost, float empty_bonus, int max_depth) {
  return "traversal_cost " + format_number(traversal_cost) + ", intersection_cost " +
         format_number(intersection_cost) + ", empty_bonus " + format_number(empty_bonus) + ", max_depth " +
         std::to_string(max_depth);
}

}  // namespace penumbra
