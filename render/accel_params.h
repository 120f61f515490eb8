// Accelerator build parameters from text ("bvh.max_leaf_size=4"), for the command line and,
// later, job files. Each key names one field of AccelConfig (renderer/accel/factory.h).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "renderer/accel/factory.h"

namespace penumbra {

/// Every accepted key with its default value and a one-line description, in display order.
struct AccelParamInfo {
  std::string key, default_value, description;
};
std::vector<AccelParamInfo> accel_param_keys();

/// Applies one "key=value" to `config`. Throws std::invalid_argument naming the key (with the
/// list of known keys for an unknown one) if the key is unknown or the value is not a number
/// of the field's type; ranges are checked by validate() when the accelerator is built.
void apply_accel_param(AccelConfig& config, std::string_view key_value);

}  // namespace penumbra

namespace penumbra {

/// Checks every structure's build parameters (Embree, BVH, kD-tree, grid, octree, BSP), each
/// with its own validate(). Throws std::invalid_argument naming the parameter.
void validate(const AccelConfig& config);

/// The structure `name`'s configuration from "key=value" parameters, each of which must belong
/// to `name` ("bvh.max_leaf_size=4" with accel "bvh"), validated. Throws std::invalid_argument:
/// "accel: unknown value 'x' (known: ...)", "accel_params P: a parameter of 'a', but accel is
/// 'b'", or what apply_accel_param and validate throw.
AccelConfig accel_config(const std::string& name, const std::vector<std::string>& params);

/// Every structure the factory builds, for help texts: "embree, bvh, ..., bsp or brute".
std::string accelerator_list();

}  // namespace penumbra
