// Tests for io/render_settings: canonical text is sorted and escaped so that no value can forge
// a line, parses back exactly, refuses anything non-canonical, and differences name each key.
#include "io/farm/render_settings.h"

#include <catch2/catch.hpp>
#include <stdexcept>

using namespace penumbra;
using Catch::Matchers::Contains;

TEST_CASE("settings: canonical text is sorted key=value lines with escapes", "[io][settings][quick]") {
  RenderSettings s;
  s.entries["width"] = "960";
  s.entries["camera"] = "Main = front\\back\nline\t\x01\x7f";
  s.entries["scene.sha256"] = "ab12";
  s.entries["empty"] = "";
  CHECK(canonical_text(s) ==
        "camera=Main \\= front\\\\back\\nline\\t\\x01\\x7f\n"
        "empty=\n"
        "scene.sha256=ab12\n"
        "width=960\n");
  CHECK(canonical_text(RenderSettings{}).empty());
  CHECK_THROWS_AS(canonical_text(RenderSettings{{{"", "x"}}}), std::invalid_argument);
}

TEST_CASE("settings: values with newlines and '=' cannot forge entries", "[io][settings][quick]") {
  const RenderSettings one{{{"a", "1\nb=2"}}};
  const RenderSettings two{{{"a", "1"}, {"b", "2"}}};
  const RenderSettings key{{{"a=1\nb", "2"}}};
  CHECK(canonical_text(one) != canonical_text(two));
  CHECK(canonical_text(key) != canonical_text(two));
  CHECK(parse_canonical_text(canonical_text(one)).entries == one.entries);
  CHECK(parse_canonical_text(canonical_text(key)).entries == key.entries);
}

TEST_CASE("settings: every byte value round trips", "[io][settings][quick]") {
  RenderSettings s;
  std::string all;
  for (int c = 0; c < 256; ++c) all += char(c);
  s.entries["all"] = all;
  s.entries[all] = "key with every byte";
  s.entries["\xc3\xa9t\xc3\xa9"] = "utf-8 \xe2\x9c\x93";
  const std::string text = canonical_text(s);
  CHECK(text.find('\r') == std::string::npos);
  CHECK(parse_canonical_text(text).entries == s.entries);
  CHECK(canonical_text(parse_canonical_text(text)) == text);
}

TEST_CASE("settings: malformed or non-canonical text is refused naming the line", "[io][settings][quick]") {
  CHECK(parse_canonical_text("").entries.empty());
  CHECK_THROWS_WITH(parse_canonical_text("a=1"), Contains("line 1") && Contains("newline"));
  CHECK_THROWS_WITH(parse_canonical_text("a=1\nb\n"), Contains("line 2") && Contains("'='"));
  CHECK_THROWS_WITH(parse_canonical_text("a\\=1\n"), Contains("line 1") && Contains("'='"));
  CHECK_THROWS_WITH(parse_canonical_text("=1\n"), Contains("empty key"));
  CHECK_THROWS_WITH(parse_canonical_text("b=1\na=2\n"), Contains("line 2") && Contains("increasing"));
  CHECK_THROWS_WITH(parse_canonical_text("a=1\na=2\n"), Contains("line 2") && Contains("increasing"));
  CHECK_THROWS_WITH(parse_canonical_text("a=\\q\n"), Contains("escape"));
  CHECK_THROWS_WITH(parse_canonical_text("a=x\\\n"), Contains("escape"));
  CHECK_THROWS_WITH(parse_canonical_text("a=\\x4\n"), Contains("escape"));
  CHECK_THROWS_WITH(parse_canonical_text("a=\\xZZ\n"), Contains("escape"));
  CHECK_THROWS_AS(parse_canonical_text("a=\\x41\n"), std::invalid_argument);  // 'A' needs no escape
  CHECK_THROWS_AS(parse_canonical_text("a=1=2\n"), std::invalid_argument);    // '=' in a value is escaped
  CHECK_THROWS_AS(parse_canonical_text("a=\t\n"), std::invalid_argument);     // so is a tab
}

TEST_CASE("settings: differences list each differing or missing key with both values",
          "[io][settings][quick]") {
  const RenderSettings a{{{"camera", "Main"}, {"seed", "1"}, {"width", "960"}}};
  RenderSettings b = a;
  CHECK(describe_differences(a, b).empty());
  b.entries["width"] = "480";
  b.entries.erase("seed");
  b.entries["aov"] = "N\nZ";
  CHECK(describe_differences(a, b) ==
        "  aov: stored (not set), this render 'N\\nZ'\n"
        "  seed: stored '1', this render (not set)\n"
        "  width: stored '960', this render '480'");
  CHECK(describe_differences(a, b, "a.exr", "b.exr").find("  width: a.exr '960', b.exr '480'") !=
        std::string::npos);
  b.entries["camera"] = std::string(1000, 'x');
  const std::string long_value = describe_differences(a, b);
  CHECK_THAT(long_value, Contains("  camera: stored 'Main', this render '" + std::string(160, 'x') + "...'"));
}
