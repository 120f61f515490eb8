// Tests for io/hash: SHA-256 against the FIPS 180-4 example digests, across block boundaries
// against a one-shot digest, and files against the system's sha256sum.
#include "io/files/hash.h"

#include <catch2/catch.hpp>
#include <cstdio>
#include <fstream>

#include "io/files/error.h"
#include "support/test_util.h"

using namespace penumbra;

TEST_CASE("sha256: FIPS 180-4 examples", "[io][hash][quick]") {
  CHECK(sha256_hex("") == "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  CHECK(sha256_hex("abc") == "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  CHECK(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq") ==
        "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  Sha256 million;
  const std::string chunk(1000, 'a');
  for (int i = 0; i < 1000; ++i) million.update(chunk);
  CHECK(million.finish_hex() == "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST_CASE("sha256: any split of the input gives the same digest", "[io][hash][quick]") {
  std::string data;
  for (int i = 0; i < 300; ++i) data += char(i * 7 + 3);
  const std::string whole = sha256_hex(data);
  for (size_t a = 0; a <= data.size(); a += 13)
    for (size_t b = a; b <= data.size(); b += 29) {
      Sha256 h;
      h.update(data.substr(0, a));
      h.update(data.substr(a, b - a));
      h.update(data.substr(b));
      REQUIRE(h.finish_hex() == whole);
    }
}

TEST_CASE("sha256: files agree with sha256sum; non-regular files are refused", "[io][hash][quick]") {
  const auto dir = test::temp_dir("hash");
  const auto file = dir / "data.bin";
  {
    std::ofstream out(file, std::ios::binary);
    for (int i = 0; i < 3 << 20; ++i) out.put(char((i * 2654435761u) >> 24));
  }
  const std::string ours = sha256_file(file);
  FILE* p = ::popen(("sha256sum '" + file.string() + "'").c_str(), "r");
  REQUIRE(p);
  char buf[65] = {};
  const size_t n = std::fread(buf, 1, 64, p);
  ::pclose(p);
  if (n == 64)
    CHECK(ours == std::string(buf, 64));
  else
    test::skip("sha256sum is not available");
  CHECK_THROWS_AS(sha256_file(dir), InputError);
  CHECK_THROWS_AS(sha256_file(dir / "missing"), InputError);
}

TEST_CASE("sha256: an empty update may pass a null pointer", "[io][hash][quick]") {
  Sha256 h;
  h.update(nullptr, 0);
  h.update("abc");
  h.update(nullptr, 0);
  CHECK(h.finish_hex() == sha256_hex("abc"));
}

TEST_CASE("sha256_of_files: content and relative names, not the folder", "[io][hash][quick]") {
  const auto a = test::temp_dir("hash_set_a"), b = test::temp_dir("hash_set_b");
  for (const auto& dir : {a, b}) {
    std::filesystem::create_directories(dir / "tex");
    std::ofstream(dir / "scene.gltf") << "{\"asset\": {}}";
    std::ofstream(dir / "tex" / "wood.png") << "pixels";
  }
  const auto set = [](const std::filesystem::path& d) {
    return sha256_of_files({d / "scene.gltf", std::filesystem::canonical(d / "tex" / "wood.png")});
  };
  const std::string original = set(a);
  CHECK(set(b) == original);                          // the same files elsewhere
  std::ofstream(b / "tex" / "wood.png") << "pixelz";  // same size, other bytes
  CHECK(set(b) != original);
  std::filesystem::rename(a / "tex" / "wood.png", a / "tex" / "pine.png");  // same bytes, other name
  CHECK(sha256_of_files({a / "scene.gltf", a / "tex" / "pine.png"}) != original);
  CHECK_THROWS_AS(sha256_of_set({a / "scene.gltf"}, {}), std::invalid_argument);
}
