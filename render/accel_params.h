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
