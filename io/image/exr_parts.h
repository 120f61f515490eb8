// Reading and writing an OpenEXR file part by part in its native channel types, shared by
// `penumbra merge` and `penumbra denoise`: the header check that comes before OpenImageIO sees
// the file, the parts' specs, and the atomic multi-part write.
#pragma once

#include <OpenImageIO/deepdata.h>
#include <OpenImageIO/imageio.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "io/image/image_output.h"

namespace penumbra::exr_parts {

/// Bytes of one EXR part's pixels: its data window, or its display window when `full`.
double image_bytes(const OIIO::ImageSpec& spec, bool full);

/// What check_exr_header learnt of a file's header.
struct ExrHeaderInfo {
  uint64_t end = 0;          ///< the offset of the first byte after the header(s): the chunk table
  bool multipart = false;    ///< the version field's multi-part flag
  int64_t chunk_count = -1;  ///< the first header's chunkCount attribute, or -1 without one
};

/// Throws InputError naming `path` unless its header (of a file of `size` bytes) is one
/// OpenImageIO can read safely: attributes that describe their own bytes, windows of at most
/// 65536 pixels a side; not deep unless `deep`.
ExrHeaderInfo check_exr_header(const std::filesystem::path& path, uint64_t size, bool deep = false);

/// Bytes a single-part deep scanline file (checked by check_exr_header with `info`) decodes to,
/// bounded from its chunk table before any chunk is read: the unpacked sample data every chunk
/// declares, and 16 bytes a pixel of `pixels` for the sample counts. Throws InputError naming the
/// file when it is multi-part, its chunk table or a chunk's sizes point outside the file, or the
/// bound exceeds `max_bytes` (OpenEXR allocates what a chunk declares before decoding it).
uint64_t check_deep_chunks(const std::filesystem::path& path, uint64_t size, const ExrHeaderInfo& info,
                           uint64_t pixels, uint64_t max_bytes);

/// Sets the attributes every Penumbra EXR carries (colour space, software) and those of `options`
/// (string, float and matrix metadata).
void set_attributes(OIIO::ImageSpec& spec, const ExrOptions& options);

/// Whether the file starts as a deep OpenEXR does (its version field's non-image flag), read from
/// its first 8 bytes before any other check; false for anything else.
bool is_deep_exr(const std::filesystem::path& path);

/// Writes one deep part (`spec` with spec.deep, `data` its samples) to `out` atomically, as
/// write_frame does; `sha256`, if not null, receives the file's SHA-256.
void write_deep_frame(const std::filesystem::path& out, const OIIO::ImageSpec& spec,
                      const OIIO::DeepData& data, std::string* sha256 = nullptr);

/// The file opened for reading; throws InputError naming it if it is not a readable OpenEXR.
std::unique_ptr<OIIO::ImageInput> open_part(const std::string& name);

/// The specs of every EXR part of `in`, checked to share one non-empty data window inside one
/// display window at the origin (not deep). Throws InputError naming `name`.
std::vector<OIIO::ImageSpec> read_specs(OIIO::ImageInput& in, const std::string& name);

/// Writes `specs` with `pixels` (per part, its data window in the part's native channel types;
/// with `whole_frame`, the specs' windows are widened to the display window and `pixels` cover
/// it) to `out` atomically; `sha256`, if not null, receives the file's SHA-256.
void write_frame(const std::filesystem::path& out, std::vector<OIIO::ImageSpec> specs,
                 const std::vector<std::vector<unsigned char>>& pixels, bool whole_frame = true,
                 std::string* sha256 = nullptr);

/// Cryptomatte manifests kept in sidecar files (cryptomatte/<key>/manif_file, relative to the
/// EXR) follow the image: each is copied from beside `first` to beside `out` ("OUT.{name}.json")
/// and the attribute renamed in every part's header.
void move_crypto_sidecars(const std::filesystem::path& first, const std::filesystem::path& out,
                          std::vector<OIIO::ImageSpec>& specs);

}  // namespace penumbra::exr_parts
