// The id AOV's name manifest.
#include "io/gltf/id_manifest.h"

#include <cstdio>
#include <set>

namespace penumbra {

std::string json_quote(const std::string& v) {
  std::string r = "\"";
  for (unsigned char c : v) {
    if (c == '"' || c == '\\') {
      r += '\\';
      r += char(c);
    } else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      r += buf;
    } else {
      r += char(c);
    }
  }
  return r + "\"";
}

std::string id_manifest(const Scene& scene, const GltfInfo& info) {
  std::set<int> nodes;
  for (const auto& inst : scene.instances)
    if (inst.node >= 0) nodes.insert(inst.node);
  std::string j = "{\"object\": {";
  bool first = true;
  for (int n : nodes) {
    const std::string name =
        size_t(n) < info.node_names.size() ? info.node_names[size_t(n)] : "nodes[" + std::to_string(n) + "]";
    j += (first ? "" : ", ") + json_quote(std::to_string(n + 1)) + ": " + json_quote(name);
    first = false;
  }
  j += "}, \"material\": {";
  for (size_t m = 0; m < scene.materials.size(); ++m)
    j += (m ? ", " : "") + json_quote(std::to_string(m + 1)) + ": " + json_quote(scene.materials[m].name);
  return j + "}}";
}

}  // namespace penumbra
