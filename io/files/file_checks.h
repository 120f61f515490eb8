// Checks on the files Penumbra reads: every input path is a regular file of bounded size
// before it is opened, so a FIFO, a device node or /dev/zero can never block or flood a read;
// a scene file in another 3D format (OBJ, FBX, USD, PLY, ...) is named as such by its extension
// or its first bytes. Also the byte-count formatting shared by budget and size messages.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace penumbra {

/// How many leading bytes of a scene file scene_file_format() looks at.
inline constexpr uint64_t kSceneSniffBytes = 4096;

/// Returns the size of `path` (symlinks followed). Throws InputError(path, element, reason)
/// unless it is a regular file of at most `max_bytes` bytes; the reason says what the path is
/// instead ("does not exist", "is a FIFO, not a regular file", "is 3.0 GiB, over the 2.0 GiB
/// limit"). `element` names the reference in the scene or the option ("buffers[2]", "--env").
uint64_t check_input_file(const std::filesystem::path& path, const std::string& element, uint64_t max_bytes);

/// What kind of file system object `path` is, for messages: "a regular file", "a directory",
/// "a FIFO", "a character device", "a block device", "a socket", "a symbolic link" (only when
/// not followed), "nothing (it does not exist)".
std::string describe_file_type(const std::filesystem::path& path, bool follow_symlinks = true);

/// What a scene file that is not glTF is, for the message that says so: "a Wavefront OBJ file",
/// "a PLY (Stanford polygon) file", "an FBX file", "a USD file", "an STL file", "an Alembic
/// file", "a Blender file", "a COLLADA file", an image or archive kind, or "not a glTF file" for
/// other bytes. Decided by the extension of `path` (case-insensitive: .obj, .fbx, .usd, .usda,
/// .usdc, .usdz, .ply, .stl, .abc, .blend, .dae), else by `head`, the file's first bytes (up to
/// kSceneSniffBytes), and its `size`: a format's signature ("ply\n", OBJ statements, "solid",
/// the binary STL length, "Kaydara FBX Binary", "#usda", "PXR-USDC", "Ogawa", "BLENDER",
/// "<COLLADA"). Empty when the file may be glTF: the GLB magic "glTF", or a JSON object ('{'
/// after blanks and a UTF-8 byte-order mark).
std::string scene_file_format(const std::filesystem::path& path, std::string_view head, uint64_t size);

/// Throws InputError(path, "", "this is a Wavefront OBJ file; Penumbra reads glTF 2.0 (.gltf,
/// .glb) — convert it, e.g. with Blender's glTF exporter (...)") when scene_file_format() names
/// a format; the conversion hint is given for the formats Blender imports.
void check_gltf_file_format(const std::filesystem::path& path, std::string_view head, uint64_t size);

/// 1536 -> "1.5 KiB", 3 << 30 -> "3.0 GiB"; below 1 KiB: "512 bytes".
std::string format_bytes(uint64_t bytes);

}  // namespace penumbra
