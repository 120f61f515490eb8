// Contact sheets: the display images of a frame range (a turntable, a shot) tiled in a grid,
// left to right and top to bottom, into one image for review.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

namespace penumbra {

/// Pixels between the sheet's cells (and around them), left transparent or black.
inline constexpr int kContactSheetGap = 2;

/// The grid of a sheet: `columns` x `rows` cells of `cell_width` x `cell_height`.
struct ContactSheetLayout {
  int columns = 0, rows = 0, cell_width = 0, cell_height = 0;
  int width() const { return columns * (cell_width + kContactSheetGap) + kContactSheetGap; }
  int height() const { return rows * (cell_height + kContactSheetGap) + kContactSheetGap; }
};

/// The grid for `images` cells: `columns` of them (0: the smallest count that makes the sheet
/// no taller than wide for cells of the given size), as many rows as needed.
ContactSheetLayout contact_sheet_layout(size_t images, int columns, int cell_width, int cell_height);

/// Throws InputError naming `out` when a sheet of `images` cells of cell_width x cell_height
/// with `channels` 8-bit channels would exceed 65536 pixels a side or `max_bytes`.
void check_contact_sheet_size(size_t images, int columns, int cell_width, int cell_height, int channels,
                              const std::filesystem::path& out, uint64_t max_bytes);

/// check_contact_sheet_size() for `images` cells the size and channel count of the image in
/// `first` (its header only is read). Throws InputError naming the file if it cannot be read.
void check_contact_sheet_size(const std::filesystem::path& first, size_t images, int columns,
                              const std::filesystem::path& out, uint64_t max_bytes);

/// Reads every image (8 bits per channel; all must have one size and channel count), tiles them
/// in order and writes the sheet to `out` atomically, in the format its extension names.
/// Throws InputError naming the file for an unreadable image or one that does not match the
/// first, or a sheet larger than `max_bytes` or 65536 pixels a side; std::runtime_error for a
/// failed write (the destination is unchanged then).
void write_contact_sheet(const std::vector<std::filesystem::path>& images, int columns,
                         const std::filesystem::path& out, uint64_t max_bytes);

}  // namespace penumbra
