// The glTF loader's file-access phase: reading input files (regular files of bounded size
// only), the GLB container (glTF 2.0 spec, "GLB File Format Specification") and resolving
// buffer and image URIs against the scene folder under the URI policy, and the file sandbox
// tinygltf reads through. Internal to io/gltf/; it neither parses JSON nor knows the glTF schema.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace tinygltf {
class TinyGLTF;
}

namespace penumbra::gltf {

/// The bytes of `path` (at most its first `prefix_bytes`) after check_input_file(path, element,
/// max_bytes). The file is opened without blocking and checked again on the open descriptor, so
/// a path swapped for a FIFO or a device after the first check cannot stall or flood the read.
/// Throws InputError.
std::vector<unsigned char> read_input_file(const std::filesystem::path& path, const std::string& element,
                                           uint64_t max_bytes, uint64_t prefix_bytes = UINT64_MAX);

/// Where the chunks of a GLB file are.
struct GlbLayout {
  std::string_view json;              ///< the JSON chunk's data (chunk 0)
  uint64_t bin_bytes = 0;             ///< the BIN chunk's data length; 0 if there is no BIN chunk
  uint64_t kept_length = 0;           ///< header + JSON chunk + BIN chunk: the prefix tinygltf reads
  std::vector<std::string> warnings;  ///< one per chunk of unknown type, each naming it
};

/// Validates the GLB container in `bytes`: the 12-byte header (magic "glTF", version 2, a length
/// within the file), then chunks of (uint32 length, uint32 type, data) starting on 4-byte
/// boundaries. Chunk 0 must be JSON; a BIN chunk may only be chunk 1 and appear once. Chunks of
/// unknown type are ignored, as the spec requires, with a warning; they can only follow JSON and
/// BIN, so the first kept_length bytes (with the header's length set to it) are a clean GLB.
/// Throws InputError(file, "GLB header" or "GLB chunk i", reason).
GlbLayout parse_glb(const std::string& file, std::span<const unsigned char> bytes);

/// true for "data:..." URIs (embedded data, decoded by tinygltf).
bool is_data_uri(std::string_view uri);

/// `uri` percent-decoded exactly as tinygltf decodes it before joining it to the base folder
/// ("%20" and "+" become a space).
std::string decode_uri(std::string_view uri);

/// The file an external (non-data) URI names and whether it may be read.
struct ResolvedUri {
  std::filesystem::path path;  ///< decoded and resolved against the scene folder, canonical
  uint64_t size = 0;           ///< the file's size in bytes, if it may be read
  bool by_policy = false;      ///< refused by the URI policy (not for what the target is)
  std::string refusal;         ///< empty: it may be read; else why not, e.g. "refused by policy:
                               ///< it resolves to '/etc/passwd', outside the scene folder ..."
                               ///< or "'/s/a.bin': file not found"
};

/// Resolves `uri` against `root` (the canonical scene folder). Without `allow_external`, a URI
/// resolving outside `root` (absolute paths, "..") is refused by policy; any target must also
/// pass check_input_file (a regular file of at most `max_bytes`).
ResolvedUri resolve_uri(const std::string& uri, const std::filesystem::path& root, bool allow_external,
                        uint64_t max_bytes);

/// The files tinygltf may read: only those resolved and checked before parsing (resolve_uri),
/// each under the name tinygltf will ask for (sandbox_name()).
struct FileSandbox {
  std::map<std::string, std::filesystem::path> served;  ///< tinygltf's path -> the checked file
  uint64_t max_bytes = 0;                               ///< per file, as in read_input_file()
  std::vector<std::filesystem::path>* read = nullptr;
  std::vector<std::string>* read_sha256 =
      nullptr;  ///< SHA-256 of each `read` file's bytes   ///< every file read, in order, once each
};

/// The path tinygltf asks for when it reads `decoded_uri` against `base` (its JoinPath).
std::string sandbox_name(const std::string& base, const std::string& decoded_uri);

/// Points tinygltf's file callbacks at `box` (which must outlive the parse): existence and reads
/// only for served files, no ~ or $VAR expansion, no writes.
void install_sandbox(tinygltf::TinyGLTF& parser, FileSandbox& box);

}  // namespace penumbra::gltf
