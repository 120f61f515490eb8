// Canonical settings text: escaping, strict parsing and a readable list of differences.
#include "io/farm/render_settings.h"

#include <stdexcept>

namespace penumbra {

namespace {

constexpr size_t kShownValueBytes = 160;

void append_escaped(std::string& out, std::string_view text) {
  static const char* digits = "0123456789abcdef";
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '\\') {
      out += "\\\\";
    } else if (c == '=') {
      out += "\\=";
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\t') {
      out += "\\t";
    } else if (c < 0x20 || c == 0x7f) {
      out += "\\x";
      out += digits[c >> 4];
      out += digits[c & 15];
    } else {
      out += ch;
    }
  }
}

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

// Undoes append_escaped on one field; throws std::invalid_argument naming `line` on a bad
// escape.
std::string unescape(std::string_view field, size_t line) {
  std::string out;
  for (size_t i = 0; i < field.size(); ++i) {
    if (field[i] != '\\') {
      out += field[i];
      continue;
    }
    const auto bad = [&] {
      return std::invalid_argument("line " + std::to_string(line) + ": invalid escape");
    };
    if (++i >= field.size()) throw bad();
    static constexpr std::string_view kNamed = "\\=nrt", kNamedBytes = "\\=\n\r\t";
    if (const size_t named = kNamed.find(field[i]); named != std::string_view::npos) {
      out += kNamedBytes[named];
    } else if (field[i] == 'x' && i + 2 < field.size() && hex_digit(field[i + 1]) >= 0 &&
               hex_digit(field[i + 2]) >= 0) {
      out += char(hex_digit(field[i + 1]) * 16 + hex_digit(field[i + 2]));
      i += 2;
    } else {
      throw bad();
    }
  }
  return out;
}

std::string shown(const std::map<std::string, std::string>& entries, const std::string& key) {
  const auto it = entries.find(key);
  if (it == entries.end()) return "(not set)";
  std::string text;
  append_escaped(text, it->second);
  if (text.size() > kShownValueBytes) text = text.substr(0, kShownValueBytes) + "...";
  return "'" + text + "'";
}

}  // namespace

std::string canonical_text(const RenderSettings& settings) {
  std::string text;
  for (const auto& [key, value] : settings.entries) {
    if (key.empty()) throw std::invalid_argument("render settings: empty key");
    append_escaped(text, key);
    text += '=';
    append_escaped(text, value);
    text += '\n';
  }
  return text;
}

RenderSettings parse_canonical_text(std::string_view text) {
  RenderSettings settings;
  size_t line = 0;
  for (size_t start = 0; start < text.size();) {
    ++line;
    const size_t end = text.find('\n', start);
    if (end == std::string_view::npos)
      throw std::invalid_argument("line " + std::to_string(line) + ": no final newline");
    const std::string_view row = text.substr(start, end - start);
    // The first '=' not escaped by a backslash splits key and value.
    size_t split = std::string_view::npos;
    for (size_t i = 0; i < row.size(); ++i) {
      if (row[i] == '\\') {
        ++i;
      } else if (row[i] == '=') {
        split = i;
        break;
      }
    }
    if (split == std::string_view::npos)
      throw std::invalid_argument("line " + std::to_string(line) + ": no '='");
    std::string key = unescape(row.substr(0, split), line);
    std::string value = unescape(row.substr(split + 1), line);
    if (key.empty()) throw std::invalid_argument("line " + std::to_string(line) + ": empty key");
    if (!settings.entries.empty() && !(settings.entries.rbegin()->first < key))
      throw std::invalid_argument("line " + std::to_string(line) + ": keys not strictly increasing");
    settings.entries.emplace_hint(settings.entries.end(), std::move(key), std::move(value));
    start = end + 1;
  }
  if (canonical_text(settings) != text)
    throw std::invalid_argument("not in canonical form (non-canonical escapes)");
  return settings;
}

std::string describe_differences(const RenderSettings& stored, const RenderSettings& current,
                                 std::string_view stored_label, std::string_view current_label) {
  std::string out;
  const auto report = [&](const std::string& key) {
    if (!out.empty()) out += '\n';
    std::string shown_key;
    append_escaped(shown_key, key);
    out += "  " + shown_key + ": " + std::string(stored_label) + " " + shown(stored.entries, key) + ", " +
           std::string(current_label) + " " + shown(current.entries, key);
  };
  // Both maps are sorted: walk them together so every key is reported once, in order.
  auto a = stored.entries.begin(), b = current.entries.begin();
  while (a != stored.entries.end() || b != current.entries.end()) {
    if (b == current.entries.end() || (a != stored.entries.end() && a->first < b->first)) {
      report((a++)->first);
    } else if (a == stored.entries.end() || b->first < a->first) {
      report((b++)->first);
    } else {
      if (a->second != b->second) report(a->first);
      ++a, ++b;
    }
  }
  return out;
}

}  // namespace penumbra
