// The parse phase: the scene file under the budget, GLB, JSON depth, the loader's own DOM for the
// raw-JSON checks, charges and URI resolution, then tinygltf with sandboxed file access.
#include "io/gltf/parse.h"

#include <tiny_gltf.h>

#include <cstring>
#include <new>
#include <nlohmann/json.hpp>

#include "io/files/file_checks.h"
#include "io/files/hash.h"
#include "io/gltf/file_access.h"
#include "io/gltf/images.h"
#include "io/gltf/json_checks.h"
#include "io/gltf/meshes.h"

namespace penumbra::gltf {

namespace fs = std::filesystem;

namespace {

// Parsing a JSON text of n bytes holds about kParsedBytesPerJsonByte * n bytes: the text itself
// (1x) and tinygltf's copy of a GLB JSON chunk (1x); the nlohmann DOM (kJsonDomBytesPerByte,
// built once by the loader's own checks, then again by tinygltf); the strings and number arrays
// tinygltf copies into its Model (3x; the fixed-size part of each element is charged per element,
// see charge_elements()). Measured with mallinfo2 and the peak RSS on generated files: the
// DOM is 7.8x the text for 10^5 named nodes with TRS (12 MB), 9.9x for 10^6 bare nodes ("{}",
// 9.4 MB) and 10.8x for 10^6 {"mesh":0} nodes (17 MB); the Model's variable part 2.3x.
constexpr uint64_t kJsonDomBytesPerByte = 11;
constexpr uint64_t kParsedBytesPerJsonByte = 1 + 1 + kJsonDomBytesPerByte + 3;

// Bytes the conversion allocates per node beyond tinygltf's Node: its name in GltfInfo, the world
// transform and the traversal stack entry, two parent links, two flags, the scene-root set entry
// (a red-black tree node), the scene's root list and the animated pose (NodePose).
constexpr uint64_t kLoaderBytesPerNode =
    sizeof(std::string) + 2 * sizeof(Transform) + 8 + 2 * sizeof(int) + 2 + 48 + sizeof(int) + 112;

// Charges the fixed-size part of every element tinygltf's Model and the conversion will hold for
// it, counted on the DOM before tinygltf parses. The variable part (names, number arrays) is in
// the JSON text's estimate (kParsedBytesPerJsonByte).
void charge_elements(const nlohmann::json& doc, MemoryBudget& budget) {
  struct Cost {
    const char* array;
    uint64_t bytes;
  };
  const Cost costs[] = {
      {"nodes", sizeof(tinygltf::Node) + kLoaderBytesPerNode},
      {"meshes", sizeof(tinygltf::Mesh) + sizeof(std::vector<LocalPrimitive>)},
      {"accessors", sizeof(tinygltf::Accessor)},
      {"bufferViews", sizeof(tinygltf::BufferView)},
      {"buffers", sizeof(tinygltf::Buffer)},
      {"materials", sizeof(tinygltf::Material) + sizeof(Material)},
      {"textures", sizeof(tinygltf::Texture)},
      {"images", sizeof(tinygltf::Image)},
      {"samplers", sizeof(tinygltf::Sampler)},
      {"cameras", sizeof(tinygltf::Camera) + sizeof(Camera)},
      {"skins", sizeof(tinygltf::Skin)},
      {"animations", sizeof(tinygltf::Animation)},
      {"scenes", sizeof(tinygltf::Scene) + sizeof(std::string)},
  };
  for (const Cost& c : costs) {
    const auto it = doc.find(c.array);
    if (it == doc.end() || !it->is_array() || it->empty()) continue;
    budget.charge(it->size() * c.bytes, c.array, std::to_string(it->size()) + " " + c.array + " need");
  }
  // Nested elements: primitives (tinygltf's and the decoded form), animation channels and samplers.
  uint64_t primitives = 0, channels = 0, samplers = 0;
  if (const auto m = doc.find("meshes"); m != doc.end())
    for (const auto& mesh : *m)
      if (const auto p = mesh.find("primitives"); p != mesh.end()) primitives += p->size();
  if (const auto a = doc.find("animations"); a != doc.end())
    for (const auto& anim : *a) {
      if (const auto c = anim.find("channels"); c != anim.end()) channels += c->size();
      if (const auto sm = anim.find("samplers"); sm != anim.end()) samplers += sm->size();
    }
  budget.charge(primitives * (sizeof(tinygltf::Primitive) + sizeof(LocalPrimitive)), "meshes",
                std::to_string(primitives) + " primitives need");
  budget.charge(channels * sizeof(tinygltf::AnimationChannel) + samplers * sizeof(tinygltf::AnimationSampler),
                "animations",
                std::to_string(channels) + " channels and " + std::to_string(samplers) + " samplers need");
}

// True for a buffer that only EXT_/KHR_meshopt_compression's decoding fills (no uri, the
// extension's fallback flag): it is never read, and decoding charges what it writes.
bool is_meshopt_fallback(const nlohmann::json& b) {
  if (!b.is_object() || b.contains("uri") || !b.contains("extensions") || !b["extensions"].is_object())
    return false;
  const auto& x = b["extensions"];
  for (const char* name : {"EXT_meshopt_compression", "KHR_meshopt_compression"})
    if (x.contains(name) && x[name].is_object() && x[name].value("fallback", false) == true) return true;
  return false;
}

// Reads the scene file. Before the whole file is read, the JSON text's parsed size is charged
// (from the file size, or a GLB's JSON chunk length), and a GLB's binary rest.
std::vector<unsigned char> read_scene_file(const fs::path& file, uint64_t max_file_bytes,
                                           MemoryBudget& budget) {
  const std::string name = file.string();
  const uint64_t size = check_input_file(file, "", max_file_bytes);
  const std::vector<unsigned char> head = read_input_file(file, "", max_file_bytes, 20);
  uint64_t json = size;
  if (head.size() >= 4 && std::memcmp(head.data(), "glTF", 4) == 0) {
    uint32_t chunk = 0;
    if (head.size() >= 16) std::memcpy(&chunk, head.data() + 12, 4);
    json = std::min<uint64_t>(chunk, size);
  }
  const uint64_t parsed = json * kParsedBytesPerJsonByte;
  if (parsed > budget.limit() - budget.used())
    throw InputError(name, "",
                     "the JSON text (" + format_bytes(json) + ") needs about " + format_bytes(parsed) +
                         " parsed, over the " + format_bytes(budget.limit()) + " budget");
  budget.charge(parsed, "", "the parsed JSON needs");
  if (size > json) budget.charge(size - json, "GLB", "the binary chunk needs");
  std::vector<unsigned char> bytes = read_input_file(file, "", max_file_bytes);
  if (bytes.size() != size) throw InputError(name, "", "the file changed size while it was read");
  return bytes;
}

// Resolves and checks every external buffer and image URI before tinygltf reads anything: a
// buffer that may not be read is an error, an image a warning (its textures are ignored). The
// readable files are served to tinygltf under the names it will ask for, and charged.
void resolve_external_files(const nlohmann::json& doc, const std::string& file, const fs::path& root,
                            const GltfLoadOptions& options, FileSandbox& box, MemoryBudget& budget,
                            std::vector<std::string>& warnings) {
  for (const char* array : {"buffers", "images"}) {
    const auto list = doc.find(array);
    if (list == doc.end()) continue;
    const bool is_buffer = array[0] == 'b';
    for (size_t i = 0; i < list->size(); ++i) {
      const std::string where = idx(array, i);
      const auto& element = (*list)[i];
      const auto uri_it = element.find("uri");
      if (uri_it == element.end()) continue;
      if (!uri_it->is_string()) throw InputError(file, where + ".uri", "must be a string");
      const std::string uri = uri_it->get<std::string>();
      if (is_data_uri(uri)) continue;
      const ResolvedUri r = resolve_uri(uri, root, options.allow_external_uris, options.max_file_bytes);
      std::string problem;
      if (!r.refusal.empty()) problem = r.by_policy ? r.refusal : "cannot be read: " + r.refusal;
      const uint64_t declared =
          is_buffer && element.contains("byteLength") ? element["byteLength"].get<uint64_t>() : 0;
      if (problem.empty() && is_buffer && r.size != declared)
        problem = "names '" + r.path.string() + "', a file of " + std::to_string(r.size) +
                  " bytes, but the buffer's byteLength is " + std::to_string(declared);
      if (!problem.empty()) {
        if (is_buffer) throw InputError(file, where, "URI '" + uri + "' " + problem);
        warnings.push_back(where + ": URI '" + uri + "' " + problem + "; the image is not read");
        continue;
      }
      // Buffers are charged by byteLength (below); an image's encoded bytes are held twice
      // while tinygltf hands them over.
      if (!is_buffer) budget.charge(2 * r.size, where, "its encoded bytes need");
      box.served[sandbox_name(root.string(), decode_uri(uri))] = r.path;
    }
  }
  if (const auto buffers = doc.find("buffers"); buffers != doc.end())
    for (size_t i = 0; i < buffers->size(); ++i)
      if ((*buffers)[i].contains("byteLength") && !is_meshopt_fallback((*buffers)[i]))
        budget.charge((*buffers)[i]["byteLength"].get<uint64_t>(), idx("buffers", i), "its data needs");
}

// The JSON checks that need the DOM, run on a DOM of the loader's own that is freed before
// tinygltf builds its own: schema checks, element and buffer charges, the vendor extensions,
// URI resolution.
void check_document(std::string_view json, const std::string& file, const fs::path& root,
                    const GltfLoadOptions& options, FileSandbox& box, MemoryBudget& budget,
                    std::vector<std::string>& warnings, VendorExtensions& vendor) {
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(json.begin(), json.end());
  } catch (const nlohmann::json::exception& e) {
    throw InputError(file, "JSON", std::string("parse error: ") + e.what());
  } catch (const std::bad_alloc&) {
    throw InputError(file, "JSON", "out of memory while parsing");
  }
  check_gltf_json(doc, file);
  charge_elements(doc, budget);
  vendor.shapes = read_node_shapes(doc, file, budget);
  vendor.procedurals = read_material_procedurals(doc, file, budget);
  resolve_external_files(doc, file, root, options, box, budget, warnings);
}

// tinygltf's error or warning text on one line, trailing blanks removed.
std::string one_line(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  for (auto& c : s)
    if (c == '\n') c = ';';
  return s;
}

// Three layouts tinygltf refuses, made acceptable before it parses the JSON:
// - a primitive whose indices accessor has no bufferView, which is how KHR_draco_mesh_compression
//   primitives declare their decoded indices: such accessors are given the primitive's Draco
//   bufferView (decompress_model() then points them at the decoded indices);
// - a buffer without a uri other than a GLB's first, which is how EXT_/KHR_meshopt_compression
//   declare the fallback buffer that decoding fills: such buffers become 4 zero bytes
//   (decompress_model() gives every compressed bufferView a buffer of its own);
// - a KHR_animation_pointer channel, whose target has no node: tinygltf drops channels without
//   one, so such targets get node 0 (unused: the pointer names the target).
// Returns the rewritten JSON, or an empty string when nothing needs it.
std::string prepare_for_tinygltf(std::string_view json) {
  if (json.find("KHR_draco_mesh_compression") == std::string_view::npos &&
      json.find("meshopt_compression") == std::string_view::npos &&
      json.find("KHR_animation_pointer") == std::string_view::npos)
    return {};
  nlohmann::json doc = nlohmann::json::parse(json, nullptr, false);
  if (doc.is_discarded() || !doc.is_object()) return {};
  bool changed = false;
  if (doc.contains("animations") && doc["animations"].is_array())
    for (auto& a : doc["animations"]) {
      if (!a.is_object() || !a.contains("channels") || !a["channels"].is_array()) continue;
      for (auto& ch : a["channels"]) {
        if (!ch.is_object() || !ch.contains("target") || !ch["target"].is_object()) continue;
        auto& target = ch["target"];
        if (target.value("path", "") != "pointer" || target.contains("node")) continue;
        target["node"] = 0;
        changed = true;
      }
    }
  if (doc.contains("buffers") && doc["buffers"].is_array()) {
    for (auto& b : doc["buffers"]) {
      if (!is_meshopt_fallback(b)) continue;
      b["uri"] = "data:application/octet-stream;base64,AAAAAA==";
      b["byteLength"] = 4;
      changed = true;
    }
  }
  if (!doc.contains("meshes") || !doc["meshes"].is_array() || !doc.contains("accessors") ||
      !doc["accessors"].is_array())
    return changed ? doc.dump() : std::string();
  auto& accessors = doc["accessors"];
  for (auto& mesh : doc["meshes"]) {
    if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
    for (auto& prim : mesh["primitives"]) {
      if (!prim.is_object() || !prim.contains("indices") || !prim["indices"].is_number_unsigned()) continue;
      const auto ext = prim.find("extensions");
      if (ext == prim.end() || !ext->is_object() || !ext->contains("KHR_draco_mesh_compression")) continue;
      const auto& draco = (*ext)["KHR_draco_mesh_compression"];
      if (!draco.is_object() || !draco.contains("bufferView") || !draco["bufferView"].is_number_unsigned())
        continue;
      const size_t a = prim["indices"].get<size_t>();
      if (a >= accessors.size() || !accessors[a].is_object() || accessors[a].contains("bufferView")) continue;
      accessors[a]["bufferView"] = draco["bufferView"];
      changed = true;
    }
  }
  return changed ? doc.dump() : std::string();
}

// `bytes` with its JSON (the whole file, or a GLB's JSON chunk of `glb_json_length` bytes)
// replaced by `json`; a GLB keeps its BIN chunk and drops what follows kept_length.
std::vector<unsigned char> replace_json(const std::vector<unsigned char>& bytes, bool is_glb,
                                        uint64_t kept_length, std::string json) {
  if (!is_glb) return {json.begin(), json.end()};
  while (json.size() % 4) json.push_back(' ');
  uint32_t old_json = 0;
  std::memcpy(&old_json, bytes.data() + 12, 4);
  const size_t rest = size_t(20 + uint64_t(old_json)), end = size_t(kept_length);
  std::vector<unsigned char> out(12 + 8 + json.size() + (end > rest ? end - rest : 0));
  const uint32_t version = 2, total = uint32_t(out.size()), length = uint32_t(json.size());
  std::memcpy(out.data(), "glTF", 4);
  std::memcpy(out.data() + 4, &version, 4);
  std::memcpy(out.data() + 8, &total, 4);
  std::memcpy(out.data() + 12, &length, 4);
  std::memcpy(out.data() + 16, "JSON", 4);
  std::memcpy(out.data() + 20, json.data(), json.size());
  if (end > rest) std::memcpy(out.data() + 20 + json.size(), bytes.data() + rest, end - rest);
  return out;
}

}  // namespace

void parse_gltf(const fs::path& file, const GltfLoadOptions& options, MemoryBudget& budget, LoadedScene& out,
                tinygltf::Model& model, VendorExtensions& vendor) {
  const std::string name = file.string();
  std::vector<unsigned char> bytes = read_scene_file(file, options.max_file_bytes, budget);
  const std::string scene_sha256 = sha256_hex({reinterpret_cast<const char*>(bytes.data()), bytes.size()});
  if (bytes.size() >= 0xffffffffu) throw InputError(name, "", "file too large for glTF (>= 4 GiB)");

  // A GLB is handed to tinygltf without the chunks of unknown type (they follow JSON and BIN).
  const bool is_glb = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
  std::string_view json(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  size_t parse_bytes = bytes.size();
  if (is_glb) {
    GlbLayout glb = parse_glb(name, bytes);
    json = glb.json;
    parse_bytes = size_t(glb.kept_length);
    const uint32_t kept = uint32_t(glb.kept_length);
    std::memcpy(bytes.data() + 8, &kept, 4);
    for (auto& w : glb.warnings) out.warnings.push_back(std::move(w));
  }
  if (json_nesting_depth(json, options.max_json_depth) > options.max_json_depth)
    throw InputError(
        name, "JSON",
        "nesting deeper than " + std::to_string(options.max_json_depth) + " levels (refused before parsing)");

  std::error_code ec;
  const fs::path root = fs::weakly_canonical(fs::absolute(file).parent_path(), ec);
  out.info.source_files.push_back(file);
  out.info.source_sha256.push_back(scene_sha256);
  FileSandbox box;
  box.max_bytes = options.max_file_bytes;
  box.read = &out.info.source_files;
  box.read_sha256 = &out.info.source_sha256;
  check_document(json, name, root, options, box, budget, out.warnings, vendor);

  const uint64_t json_bytes = json.size();
  if (std::string patched = prepare_for_tinygltf(json); !patched.empty()) {
    budget.charge(patched.size(), "JSON", "the JSON prepared for decompression needs");
    bytes = replace_json(bytes, is_glb, parse_bytes, std::move(patched));
    parse_bytes = bytes.size();
    json = {};  // pointed into the old bytes
  }

  tinygltf::TinyGLTF parser;
  install_sandbox(parser, box);
  keep_encoded_images(parser);
  std::string terr, twarn;
  bool ok = false;
  try {
    ok = is_glb
             ? parser.LoadBinaryFromMemory(&model, &terr, &twarn, bytes.data(), unsigned(parse_bytes),
                                           root.string())
             : parser.LoadASCIIFromString(&model, &terr, &twarn, reinterpret_cast<const char*>(bytes.data()),
                                          unsigned(bytes.size()), root.string());
  } catch (const std::bad_alloc&) {
    throw InputError(name, "", "out of memory while parsing (file too large or malformed)");
  } catch (const std::exception& e) {
    throw InputError(name, "", std::string("parse error: ") + e.what());
  }
  budget.release(json_bytes * kJsonDomBytesPerByte);  // tinygltf's DOM is gone
  if (!ok) throw InputError(name, "", terr.empty() ? "tinygltf could not parse the file" : one_line(terr));
  if (!twarn.empty()) out.warnings.push_back("tinygltf: " + one_line(twarn));
}

}  // namespace penumbra::gltf
