// The canonical form of everything that decides a render's pixels: key/value text pairs such as
// {"scene.sha256", "..."}, {"camera", "..."}, {"width", "960"}. Resume state and tile metadata
// store it, so state or tiles of another render are recognised and the differing keys named.
// This module serialises and compares; which keys exist is the caller's choice.
#pragma once

#include <map>
#include <string>
#include <string_view>

namespace penumbra {

/// String attribute of an EXR: SHA-256 (hex) of the scene it was rendered from.
inline constexpr const char* kSceneHashAttribute = "penumbra:scene_sha256";
/// String attribute of an EXR: canonical_text of its render's settings without the keys that
/// differ between tiles of one frame (window, crop, tile).
inline constexpr const char* kSettingsAttribute = "penumbra:settings";

/// Settings as key -> value text. Keys must be non-empty; values may be any bytes.
struct RenderSettings {
  std::map<std::string, std::string> entries;
};

/// One "key=value\n" line per entry, in bytewise key order. In keys and values the bytes '\\',
/// '=', and control bytes (below 0x20, and 0x7f) are escaped ("\\\\", "\\=", "\\n", "\\r",
/// "\\t", else "\\xHH"), so no key or value can end a line or move the '=' that splits it: equal
/// settings give equal text and different settings different text. Throws
/// std::invalid_argument on an empty key.
std::string canonical_text(const RenderSettings& settings);

/// The inverse of canonical_text. Throws std::invalid_argument saying which line is wrong
/// unless `text` is exactly canonical_text of some settings: every line ends in '\n' and holds
/// one unescaped '=', every escape is the canonical one, keys are non-empty and strictly
/// increasing. Empty text gives empty settings.
RenderSettings parse_canonical_text(std::string_view text);

/// One line per key whose value differs or that only one side has, in key order:
/// "  key: stored 'a', this render 'b'" ("(not set)" for a missing key; values escaped as in
/// canonical_text and shortened to 160 bytes), lines joined by '\n'. Empty when the settings are
/// equal. `stored_label` and `current_label` replace "stored" and "this render".
std::string describe_differences(const RenderSettings& stored, const RenderSettings& current,
                                 std::string_view stored_label = "stored",
                                 std::string_view current_label = "this render");

}  // namespace penumbra
