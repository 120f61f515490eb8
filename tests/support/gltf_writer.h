// Writes small glTF files for tests: typed accessors over one buffer, embedded as a data URI,
// written as an external .bin, or packed as GLB.
#pragma once

#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace penumbra::test {

class GltfWriter {
 public:
  nlohmann::json j = {{"asset", {{"version", "2.0"}}},
                      {"accessors", nlohmann::json::array()},
                      {"bufferViews", nlohmann::json::array()},
                      {"meshes", nlohmann::json::array()},
                      {"nodes", nlohmann::json::array()},
                      {"scenes", {{{"nodes", nlohmann::json::array()}}}},
                      {"scene", 0}};
  std::vector<uint8_t> bin;

  /// Appends raw bytes as a bufferView (4-byte aligned) and an accessor over them.
  int accessor(const void* data, size_t bytes, int component_type, size_t count, const char* type) {
    while (bin.size() % 4) bin.push_back(0);
    const size_t offset = bin.size();
    bin.resize(offset + bytes);
    std::memcpy(bin.data() + offset, data, bytes);
    j["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}});
    j["accessors"].push_back({{"bufferView", int(j["bufferViews"].size()) - 1},
                              {"componentType", component_type},
                              {"count", count},
                              {"type", type}});
    return int(j["accessors"].size()) - 1;
  }
  int positions(const std::vector<float>& xyz) {
    return accessor(xyz.data(), xyz.size() * 4, 5126, xyz.size() / 3, "VEC3");
  }
  template <class T>
  int indices(const std::vector<T>& idx) {
    const int ct = sizeof(T) == 1 ? 5121 : (sizeof(T) == 2 ? 5123 : 5125);
    return accessor(idx.data(), idx.size() * sizeof(T), ct, idx.size(), "SCALAR");
  }
  /// A FLOAT accessor over `v`, `width` components per element of `type`.
  int floats(const std::vector<float>& v, const char* type, size_t width) {
    return accessor(v.data(), v.size() * 4, 5126, v.size() / width, type);
  }
  /// Adds a channel (node, path) with its own sampler over the keys to animations[0].
  void channel(int node, const char* path, const std::vector<float>& times, const std::vector<float>& values,
               const char* type, size_t width, const char* interpolation = "LINEAR") {
    const int in = floats(times, "SCALAR", 1), out = floats(values, type, width);
    if (!j.contains("animations"))
      j["animations"] = nlohmann::json::array(
          {{{"channels", nlohmann::json::array()}, {"samplers", nlohmann::json::array()}}});
    auto& a = j["animations"][0];
    a["samplers"].push_back({{"input", in}, {"output", out}, {"interpolation", interpolation}});
    a["channels"].push_back(
        {{"sampler", int(a["samplers"].size()) - 1}, {"target", {{"node", node}, {"path", path}}}});
  }
  /// A mesh with one primitive; returns the mesh index.
  int mesh(int position_accessor, int index_accessor = -1, int mode = 4) {
    nlohmann::json prim = {{"attributes", {{"POSITION", position_accessor}}}, {"mode", mode}};
    if (index_accessor >= 0) prim["indices"] = index_accessor;
    j["meshes"].push_back({{"primitives", {prim}}});
    return int(j["meshes"].size()) - 1;
  }
  /// A mesh with one primitive and one morph target (POSITION deltas), default weight 0.
  int morph_mesh(int position_accessor, int target_accessor) {
    const int m = mesh(position_accessor);
    j["meshes"][size_t(m)]["primitives"][0]["targets"] =
        nlohmann::json::array({{{"POSITION", target_accessor}}});
    j["meshes"][size_t(m)]["weights"] = {0.0};
    return m;
  }
  /// A mesh with one primitive skinned by JOINTS_0 (4 unsigned bytes per vertex) and WEIGHTS_0
  /// (4 floats per vertex); returns the mesh index.
  int skinned_mesh(int position_accessor, const std::vector<uint8_t>& joints,
                   const std::vector<float>& weights) {
    const int ja = accessor(joints.data(), joints.size(), 5121, joints.size() / 4, "VEC4");
    const int wa = floats(weights, "VEC4", 4);
    const int m = mesh(position_accessor);
    j["meshes"][size_t(m)]["primitives"][0]["attributes"]["JOINTS_0"] = ja;
    j["meshes"][size_t(m)]["primitives"][0]["attributes"]["WEIGHTS_0"] = wa;
    return m;
  }
  /// A node (root unless `root` is false); returns its index.
  int node(nlohmann::json fields, bool root = true) {
    j["nodes"].push_back(std::move(fields));
    const int i = int(j["nodes"].size()) - 1;
    if (root) j["scenes"][0]["nodes"].push_back(i);
    return i;
  }

  static std::string base64(const std::vector<uint8_t>& data) {
    static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < data.size(); i += 3) {
      const uint32_t n = (uint32_t(data[i]) << 16) | (i + 1 < data.size() ? uint32_t(data[i + 1]) << 8 : 0) |
                         (i + 2 < data.size() ? data[i + 2] : 0);
      out += t[(n >> 18) & 63];
      out += t[(n >> 12) & 63];
      out += i + 1 < data.size() ? t[(n >> 6) & 63] : '=';
      out += i + 2 < data.size() ? t[n & 63] : '=';
    }
    return out;
  }

  /// .gltf with the buffer embedded as a data URI.
  void write_embedded(const std::filesystem::path& path) {
    nlohmann::json out = j;
    if (!bin.empty())
      out["buffers"] = {
          {{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}};
    std::ofstream(path) << out.dump();
  }
  /// .gltf next to an external buffer file `uri` (relative to the .gltf's folder).
  void write_external(const std::filesystem::path& path, const std::string& uri) {
    nlohmann::json out = j;
    out["buffers"] = {{{"byteLength", bin.size()}, {"uri", uri}}};
    std::ofstream(path) << out.dump();
    std::ofstream(path.parent_path() / uri, std::ios::binary)
        .write(reinterpret_cast<const char*>(bin.data()), std::streamsize(bin.size()));
  }
  /// Binary glTF (GLB) with JSON and BIN chunks.
  void write_glb(const std::filesystem::path& path) {
    nlohmann::json out = j;
    out["buffers"] = {{{"byteLength", bin.size()}}};
    std::string json = out.dump();
    while (json.size() % 4) json += ' ';
    std::vector<uint8_t> b = bin;
    while (b.size() % 4) b.push_back(0);
    const uint32_t total = uint32_t(12 + 8 + json.size() + 8 + b.size());
    std::ofstream f(path, std::ios::binary);
    auto u32 = [&](uint32_t v) { f.write(reinterpret_cast<const char*>(&v), 4); };
    f.write("glTF", 4);
    u32(2);
    u32(total);
    u32(uint32_t(json.size()));
    u32(0x4E4F534Au);
    f.write(json.data(), std::streamsize(json.size()));
    u32(uint32_t(b.size()));
    u32(0x004E4942u);
    f.write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
  }
};

/// A unit quad in the z = 0 plane (4 vertices, counter-clockwise seen from +z).
inline std::vector<float> quad_positions() {
  return {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
}

}  // namespace penumbra::test
