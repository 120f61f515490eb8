// Materials (io/gltf/materials.cpp): the KHR material extensions on a generated file, and
// textured corpus models rendered from the front and sampled at known places: texture
// orientation (TextureCoordinateTest), KHR_texture_transform (TextureTransformTest),
// TEXCOORD_1 (MultiUVTest) and COLOR_0 (VertexColorTest). The renders are "albedo" renders:
// no lights, ambient 1, metallic forced to 0, so a pixel's value is the base colour the
// material evaluates to there (Whitted: L = kd Ia), and expectations come from what each
// model's README says a correct viewer shows.
#include <catch2/catch.hpp>

#include "io/gltf/loader.h"
#include "io/image/image_output.h"
#include "renderer/accel/factory.h"
#include "renderer/integrators/render.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/materials/material.h"
#include "support/gltf_load.h"
#include "support/gltf_writer.h"
#include "support/image_files.h"
#include "support/test_util.h"

using namespace penumbra;
using Catch::Matchers::Contains;
using penumbra::test::GltfWriter;
using penumbra::test::write_and_load;

namespace {

struct FrontView {
  LoadedScene loaded;
  Film film;
  Bounds3f bounds;
  float half_w = 0, half_h = 0;
  Vec3f centre;
  int width = 0, height = 0;

  // Pixel value at world (x, y) seen from +z.
  Vec3f at(float x, float y) const {
    const int px = std::clamp(int((x - (centre.x - half_w)) / (2 * half_w) * float(width)), 0, width - 1);
    const int py = std::clamp(int(((centre.y + half_h) - y) / (2 * half_h) * float(height)), 0, height - 1);
    const float* p = film.pixel(px, py);
    return {p[0], p[1], p[2]};
  }
  // Mean over the world rectangle [x0,x1] x [y0,y1].
  Vec3f mean(float x0, float x1, float y0, float y1, int n = 12) const {
    Vec3f sum;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        sum +=
            at(x0 + (x1 - x0) * (float(i) + 0.5f) / float(n), y0 + (y1 - y0) * (float(j) + 0.5f) / float(n));
    return sum / float(n * n);
  }
};

// Orthographic albedo render looking down -z at the whole scene.
FrontView front_albedo(const std::filesystem::path& file, int width = 480) {
  FrontView v;
  v.loaded = load_gltf(file);
  Scene& s = v.loaded.scene;
  for (auto& m : s.materials) m.metallic = 0;
  s.lights.clear();
  v.bounds = compute_bounds(s);
  v.centre = v.bounds.center();
  const Vec3f e = v.bounds.extent();
  v.width = width;
  v.height = std::max(1, int(float(width) * e.y / e.x));
  v.half_w = e.x * 0.55f;
  v.half_h = v.half_w * float(v.height) / float(v.width);
  Camera cam;
  cam.projection = Projection::Orthographic;
  cam.eye = {v.centre.x, v.centre.y, v.bounds.hi.z + 1};
  cam.ymag = v.half_h;
  cam.znear = 0;
  cam.zfar = e.z + 10;
  RenderConfig cfg;
  cfg.width = v.width;
  cfg.height = v.height;
  cfg.spp = 4;
  cfg.whitted.ambient = {1, 1, 1};
  cfg.whitted.max_depth = 0;
  const auto accel = make_scene_accelerator("embree", s);
  v.film = render_whitted(s, *accel, cam, cfg);
  if (const char* dir = std::getenv("PENUMBRA_TEST_DUMP"))  // for looking at what a test sees
    write_exr(v.film, std::filesystem::path(dir) / (file.stem().string() + ".exr"), ExrOptions{});
  return v;
}

// A file with one quad node whose primitive uses materials[0] (for the caller to write).
GltfWriter quad_with_material() {
  GltfWriter w;
  const int m =
      w.mesh(w.positions(test::quad_positions()), w.indices(std::vector<uint8_t>{0, 1, 2, 0, 2, 3}));
  w.j["meshes"][size_t(m)]["primitives"][0]["material"] = 0;
  w.node({{"mesh", m}});
  return w;
}

float lum(Vec3f c) {
  return luminance(c);
}

}  // namespace

TEST_CASE("corpus textures: TextureCoordinateTest shows each quadrant of the image the right way up",
          "[io][corpus][texture]") {
  const auto corpus = test::corpus_dir();
  if (!corpus) return test::skip("../shared/corpus not found (set PENUMBRA_CORPUS)");
  const FrontView v =
      front_albedo(*corpus / "valid/TextureCoordinateTest/glTF-Binary/TextureCoordinateTest.glb");
  // Quad colours are the materials' factors (yellow, orange, blue, green) over a white texture.
  const Vec3f tl = v.mean(-1.0f, -0.4f, 0.5f, 0.9f), tr = v.mean(0.4f, 1.0f, 0.5f, 0.9f);
  const Vec3f bl = v.mean(-1.0f, -0.4f, -0.9f, -0.5f), br = v.mean(0.4f, 1.0f, -0.9f, -0.5f);
  CHECK(tl.x > 0.4f);
  CHECK(tl.y > 0.4f);
  CHECK(tl.z < 0.1f);
  CHECK(tr.x > 0.4f);
  CHECK(tr.y < 0.2f * tr.x);
  CHECK(bl.z > 0.4f);
  CHECK(bl.x < 0.1f);
  CHECK(br.y > 0.4f);
  CHECK(br.x < 0.1f);
  // The texture's checkered border runs from its top-left corner along part of the top and
  // left edges, so each quad is darkest at the corner of the image it shows (its outer
  // corner) and not at the two corners next to it; a flipped V axis would move the dark
  // patch to the neighbouring corner.
  struct Quad {
    float x0, x1, y0, y1;
    bool outer_left, outer_top;
  };
  const Quad quads[4] = {{-1.2f, -0.2f, 0.2f, 1.2f, true, true},
                         {0.2f, 1.2f, 0.2f, 1.2f, false, true},
                         {-1.2f, -0.2f, -1.2f, -0.2f, true, false},
                         {0.2f, 1.2f, -1.2f, -0.2f, false, false}};
  const float p = 0.3f;
  for (const Quad& q : quads) {
    // Mean of the p x p square inside the quad at its corner (left?, top?).
    auto corner = [&](bool left, bool top) {
      const float x0 = left ? q.x0 : q.x1 - p, y0 = top ? q.y1 - p : q.y0;
      return lum(v.mean(x0, x0 + p, y0, y0 + p));
    };
    const float outer = corner(q.outer_left, q.outer_top);
    CHECK(outer < 0.85f * corner(!q.outer_left, q.outer_top));
    CHECK(outer < 0.85f * corner(q.outer_left, !q.outer_top));
  }
}

TEST_CASE("corpus textures: TextureTransformTest offsets, rotation and scale read the texels the spec names",
          "[io][corpus][texture]") {
  const auto corpus = test::corpus_dir();
  if (!corpus) return test::skip("../shared/corpus not found (set PENUMBRA_CORPUS)");
  const FrontView v =
      front_albedo(*corpus / "valid/TextureTransformTest/glTF/TextureTransformTest.gltf", 640);
  const Scene& s = v.loaded.scene;
  // Each quad spans 1 x 1 around its node's translation, uv (0,0) at its top-left corner;
  // the top row's UVs run 0..0.5, the bottom row's 0..1 (README).
  auto texel = [&](int material, Vec2f uv) {
    const Texture& t = s.textures[size_t(s.materials[size_t(material)].base_color_tex.texture)];
    const Vec4f c = sample_texture(t, uv, 0);
    return Vec3f{c.x, c.y, c.z};
  };
  auto close = [](Vec3f a, Vec3f b) { return max_component(abs(a - b)) < 0.03f; };
  // Top row at a quarter of each quad (uv 0.125, 0.125 before the transform), offsets
  // (0.5, 0), (0, 0.5), (0.5, 0.5).
  const float qx[3] = {-1.1f, 0.0f, 1.1f};
  const Vec2f offset[3] = {{0.5f, 0}, {0, 0.5f}, {0.5f, 0.5f}};
  for (int i = 0; i < 3; ++i) {
    const Vec3f got = v.at(qx[i] - 0.25f, 0.55f + 0.25f);
    CHECK(close(got, texel(i, {0.125f + offset[i].x, 0.125f + offset[i].y})));
    CHECK_FALSE(close(got, texel(i, {0.125f, 0.125f})));  // "yellow: offset not applied"
  }
  // Rotation 22.5 degrees, uv' = R uv with R = [c s; -s c], sampled at uv = (0.2, 0.3).
  const float a = 0.39269908f, c = std::cos(a), sn = std::sin(a);
  const Vec2f uv{0.2f, 0.3f};
  const Vec3f rot = v.at(-1.1f - 0.5f + uv.x, -0.55f + 0.5f - uv.y);
  CHECK(close(rot, texel(3, {c * uv.x + sn * uv.y, -sn * uv.x + c * uv.y})));
  // Scale 1.5 at the same uv.
  const Vec3f scaled = v.at(0.0f - 0.5f + uv.x, -0.55f + 0.5f - uv.y);
  CHECK(close(scaled, texel(4, {1.5f * uv.x, 1.5f * uv.y})));
}

TEST_CASE("KHR_texture_transform: members of the wrong type are errors naming the member",
          "[io][gltf][texture][quick]") {
  const auto dir = test::temp_dir("texture_transform");
  const unsigned char grey[3] = {128, 128, 128};
  test::write_flat_image(dir / "grey.png", grey);
  GltfWriter w = quad_with_material();
  w.j["images"] = {{{"uri", "grey.png"}}};
  w.j["textures"] = {{{"source", 0}}};
  w.j["extensionsUsed"] = {"KHR_texture_transform"};
  auto load_with = [&](const nlohmann::json& transform) {
    w.j["materials"] = {
        {{"pbrMetallicRoughness",
          {{"baseColorTexture", {{"index", 0}, {"extensions", {{"KHR_texture_transform", transform}}}}}}}}};
    w.write_embedded(dir / "scene.gltf");
    return load_gltf(dir / "scene.gltf");
  };
  const LoadedScene good =
      load_with({{"offset", {0.5, 0.25}}, {"rotation", 0.0}, {"scale", {2, 3}}, {"texCoord", 1}});
  const TextureRef& ref = good.scene.materials.at(0).base_color_tex;
  CHECK(ref.texture == 0);
  CHECK(ref.texcoord == 1);
  CHECK(ref.m[0][0] == 2);
  CHECK(ref.m[1][1] == 3);
  CHECK(ref.m[0][2] == 0.5f);
  CHECK(ref.m[1][2] == 0.25f);
  const std::string xw =
      "materials[0].pbrMetallicRoughness.baseColorTexture.extensions.KHR_texture_transform";
  auto bad = [&](const char* key, const nlohmann::json& value, const char* expect) {
    INFO(key << " = " << value.dump());
    REQUIRE_THROWS_WITH(load_with({{key, value}}), Contains(xw + "." + key + ": " + expect));
  };
  bad("scale", "x", "must be an array of 2 numbers");
  bad("scale", {1, "x"}, "must be an array of 2 numbers");
  bad("offset", 0.5, "must be an array of 2 numbers");
  bad("offset", {{"u", 0.5}}, "must be an array of 2 numbers");
  bad("rotation", "90deg", "must be a number");
  bad("rotation", {0.5}, "must be a number");
  bad("texCoord", "1", "must be a non-negative integer");
  bad("texCoord", 0.5, "must be a non-negative integer");
  // The texture infos of material extensions are read the same way.
  w.j["materials"] = {
      {{"extensions",
        {{"KHR_materials_clearcoat",
          {{"clearcoatFactor", 1.0},
           {"clearcoatTexture",
            {{"index", 0}, {"extensions", {{"KHR_texture_transform", {{"texCoord", "1"}}}}}}}}}}}}};
  w.j["extensionsUsed"] = {"KHR_texture_transform", "KHR_materials_clearcoat"};
  w.write_embedded(dir / "scene.gltf");
  REQUIRE_THROWS_WITH(load_gltf(dir / "scene.gltf"),
                      Contains("materials[0].extensions.KHR_materials_clearcoat.clearcoatTexture.extensions."
                               "KHR_texture_transform.texCoord: must be a non-negative integer"));
}

TEST_CASE("corpus textures: VertexColorTest multiplies COLOR_0 so the hidden X marks stay hidden",
          "[io][corpus][texture]") {
  const auto corpus = test::corpus_dir();
  if (!corpus) return test::skip("../shared/corpus not found (set PENUMBRA_CORPUS)");
  const FrontView v = front_albedo(*corpus / "valid/VertexColorTest/glTF-Binary/VertexColorTest.glb");
  // The test row's three cells are multiplied by pure red, green and blue vertex colours: each
  // cell's other two channels must vanish (an engine ignoring COLOR_0 shows a cyan, magenta
  // or yellow X there).
  int checked = 0;
  for (int cell = 0; cell < 3; ++cell) {
    const float x0[3] = {-0.72f, -0.18f, 0.38f};
    const Vec3f m = v.mean(x0[cell], x0[cell] + 0.36f, 0.2f, 0.5f);
    const float own = cell == 0 ? m.x : (cell == 1 ? m.y : m.z);
    const float other =
        cell == 0 ? std::max(m.y, m.z) : (cell == 1 ? std::max(m.x, m.z) : std::max(m.x, m.y));
    CHECK(own > 0.1f);
    CHECK(other < 0.02f);
    ++checked;
  }
  CHECK(checked == 3);
}

TEST_CASE("corpus textures: MultiUVTest reads its emissive texture through TEXCOORD_1",
          "[io][corpus][texture]") {
  const auto corpus = test::corpus_dir();
  if (!corpus) return test::skip("../shared/corpus not found (set PENUMBRA_CORPUS)");
  LoadedScene ls = load_gltf(*corpus / "valid/MultiUVTest/glTF-Binary/MultiUVTest.glb");
  const Scene& s = ls.scene;
  REQUIRE(s.meshes.size() == 1);
  REQUIRE_FALSE(s.meshes[0].uvs1.empty());
  const Material& m = s.materials[0];
  REQUIRE(m.emissive_tex.texture >= 0);
  CHECK(m.emissive_tex.texcoord == 1);
  CHECK(m.base_color_tex.texcoord == 0);
  // At every vertex-centred sample the evaluated emission equals the emissive texture read at
  // TEXCOORD_1, and somewhere differs from a read at TEXCOORD_0.
  const auto accel = make_scene_accelerator("embree", s);
  int differs = 0, samples = 0;
  for (int i = 0; i < 40; ++i) {
    Ray r;
    const float a = 0.3f + 0.11f * float(i);
    r.org = {3 * std::cos(a), 0.5f * std::sin(3.0f * a), 3 * std::sin(a)};
    r.dir = normalize(Vec3f{0, 0.1f * std::cos(5.0f * a), 0} - r.org);
    Hit h;
    if (!accel->intersect(r, h)) continue;
    const SurfaceInteraction si = make_interaction(s, r, h);
    const MaterialPoint mp = eval_material(s, si);
    const Texture& t = s.textures[size_t(m.emissive_tex.texture)];
    const Vec4f via1 = sample_texture(t, si.uv[1], 0), via0 = sample_texture(t, si.uv[0], 0);
    CHECK(mp.emissive.x == Approx(m.emissive.x * via1.x).margin(1e-4));
    CHECK(mp.emissive.y == Approx(m.emissive.y * via1.y).margin(1e-4));
    if (max_component(abs(Vec3f{via1.x - via0.x, via1.y - via0.y, via1.z - via0.z})) > 0.05f) ++differs;
    ++samples;
  }
  CHECK(samples > 30);
  CHECK(differs > 0);
}

TEST_CASE("KHR_materials_ior, _specular and _transmission load; bad values name the field",
          "[io][gltf][quick]") {
  GltfWriter w = quad_with_material();
  w.j["materials"] = {
      {{"extensions",
        {{"KHR_materials_ior", {{"ior", 2.0}}},
         {"KHR_materials_specular", {{"specularFactor", 0.5}, {"specularColorFactor", {2, 0.5, 0}}}},
         {"KHR_materials_transmission", {{"transmissionFactor", 0.75}}}}}}};
  w.j["extensionsUsed"] = {"KHR_materials_ior", "KHR_materials_specular", "KHR_materials_transmission"};
  w.j["extensionsRequired"] = {"KHR_materials_transmission"};
  const LoadedScene loaded = write_and_load(w, "extmat");
  const Material& mat = loaded.scene.materials.at(0);
  CHECK(mat.ior == 2);
  CHECK(mat.specular == 0.5f);
  CHECK(mat.specular_color.x == 2);  // the colour factor may exceed 1
  CHECK(mat.specular_color.y == 0.5f);
  CHECK(mat.transmission == 0.75f);
  // ior 0 is the extension's special case (f0 = 1); between 0 and 1 it is an error.
  w.j["materials"][0]["extensions"]["KHR_materials_ior"]["ior"] = 0.0;
  CHECK(write_and_load(w, "ior0").scene.materials.at(0).ior == 0);
  w.j["materials"][0]["extensions"]["KHR_materials_ior"]["ior"] = 0.5;
  REQUIRE_THROWS_WITH(write_and_load(w, "iorbad"), Contains("materials[0].extensions.KHR_materials_ior.ior"));
  w.j["materials"][0]["extensions"]["KHR_materials_ior"]["ior"] = 1.5;
  w.j["materials"][0]["extensions"]["KHR_materials_transmission"]["transmissionFactor"] = 1.5;
  REQUIRE_THROWS_WITH(write_and_load(w, "trbad"),
                      Contains("KHR_materials_transmission.transmissionFactor") && Contains("[0, 1]"));
  w.j["materials"][0]["extensions"]["KHR_materials_transmission"]["transmissionFactor"] = 0.5;
  w.j["materials"][0]["extensions"]["KHR_materials_specular"]["specularFactor"] = "shiny";
  REQUIRE_THROWS_WITH(write_and_load(w, "spbad"),
                      Contains("KHR_materials_specular.specularFactor") && Contains("number"));
}

TEST_CASE(
    "KHR material layers (clearcoat, sheen, volume, anisotropy, iridescence, dispersion, diffuse "
    "transmission) load; bad values name the field",
    "[io][gltf][quick]") {
  GltfWriter w = quad_with_material();
  w.j["materials"] = {
      {{"extensions",
        {{"KHR_materials_clearcoat", {{"clearcoatFactor", 0.8}, {"clearcoatRoughnessFactor", 0.2}}},
         {"KHR_materials_sheen", {{"sheenColorFactor", {0.9, 0.5, 0.1}}, {"sheenRoughnessFactor", 0.4}}},
         {"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
         {"KHR_materials_volume",
          {{"thicknessFactor", 0.5}, {"attenuationDistance", 2.0}, {"attenuationColor", {0.5, 0.6, 0.7}}}},
         {"KHR_materials_anisotropy", {{"anisotropyStrength", 0.6}, {"anisotropyRotation", 1.25}}},
         {"KHR_materials_iridescence",
          {{"iridescenceFactor", 1.0},
           {"iridescenceIor", 1.8},
           {"iridescenceThicknessMinimum", 200},
           {"iridescenceThicknessMaximum", 600}}},
         {"KHR_materials_dispersion", {{"dispersion", 0.3}}},
         {"KHR_materials_diffuse_transmission",
          {{"diffuseTransmissionFactor", 0.25}, {"diffuseTransmissionColorFactor", {0.2, 0.4, 0.6}}}}}}}};
  w.j["extensionsUsed"] = {"KHR_materials_clearcoat",    "KHR_materials_sheen",
                           "KHR_materials_transmission", "KHR_materials_volume",
                           "KHR_materials_anisotropy",   "KHR_materials_iridescence",
                           "KHR_materials_dispersion",   "KHR_materials_diffuse_transmission"};
  const LoadedScene loaded = write_and_load(w, "layers");
  for (const auto& warning : loaded.warnings) CHECK(warning.find("not supported") == std::string::npos);
  const Material& mat = loaded.scene.materials.at(0);
  CHECK(mat.clearcoat == 0.8f);
  CHECK(mat.clearcoat_roughness == 0.2f);
  CHECK(mat.sheen_color.x == 0.9f);
  CHECK(mat.sheen_color.z == 0.1f);
  CHECK(mat.sheen_roughness == 0.4f);
  CHECK(mat.volume);
  CHECK(mat.attenuation_distance == 2.0f);
  CHECK(mat.attenuation_color.y == 0.6f);
  CHECK(mat.anisotropy == 0.6f);
  CHECK(mat.anisotropy_rotation == 1.25f);
  CHECK(mat.iridescence == 1.0f);
  CHECK(mat.iridescence_ior == 1.8f);
  CHECK(mat.iridescence_thickness_min == 200);
  CHECK(mat.iridescence_thickness_max == 600);
  CHECK(mat.dispersion == 0.3f);
  CHECK(mat.diffuse_transmission == 0.25f);
  CHECK(mat.diffuse_transmission_color.z == 0.6f);
  // A thickness of 0 is thin-walled.
  w.j["materials"][0]["extensions"]["KHR_materials_volume"]["thicknessFactor"] = 0.0;
  CHECK_FALSE(write_and_load(w, "thin").scene.materials.at(0).volume);
  auto bad = [&](const char* ext, const char* key, nlohmann::json value, const char* expect) {
    GltfWriter b = w;
    b.j["materials"][0]["extensions"][ext][key] = value;
    INFO(ext << "." << key);
    REQUIRE_THROWS_WITH(
        write_and_load(b, "bad"),
        Contains(std::string("materials[0].extensions.") + ext + "." + key) && Contains(expect));
  };
  bad("KHR_materials_clearcoat", "clearcoatFactor", 1.5, "[0, 1]");
  bad("KHR_materials_sheen", "sheenColorFactor", {1, 2}, "3 numbers");
  bad("KHR_materials_volume", "attenuationDistance", 0.0, "> 0");
  bad("KHR_materials_anisotropy", "anisotropyStrength", "strong", "number");
  bad("KHR_materials_iridescence", "iridescenceIor", 0.5, ">= 1");
  bad("KHR_materials_dispersion", "dispersion", -1, ">= 0");
  bad("KHR_materials_diffuse_transmission", "diffuseTransmissionFactor", 2, "[0, 1]");
  bad("KHR_materials_clearcoat", "clearcoatTexture", 3, "texture info");
}

TEST_CASE("KHR_materials_variants: a variant picks each mapping's material; unknown names list the variants",
          "[io][gltf][quick]") {
  GltfWriter w = quad_with_material();
  w.j["materials"] = {{{"name", "own"}}, {{"name", "blue"}}, {{"name", "green"}}};
  w.j["extensions"]["KHR_materials_variants"]["variants"] = {
      {{"name", "red"}}, {{"name", "blue"}}, {{"name", "green"}}};
  w.j["meshes"][0]["primitives"][0]["extensions"]["KHR_materials_variants"]["mappings"] = {
      {{"material", 1}, {"variants", {1}}}, {{"material", 2}, {"variants", {2}}}};
  w.j["extensionsUsed"] = {"KHR_materials_variants"};
  auto material_of_mesh = [&](const std::string& variant) {
    GltfLoadOptions opt;
    opt.variant = variant;
    const LoadedScene l = write_and_load(w, "variants", opt);
    CHECK(l.warnings.empty());
    CHECK(l.info.variants == std::vector<std::string>{"red", "blue", "green"});
    return l.scene.materials.at(size_t(l.scene.meshes.at(0).material)).name;
  };
  CHECK(material_of_mesh("") == "own");
  CHECK(material_of_mesh("red") == "own");  // no mapping: the primitive's own material
  CHECK(material_of_mesh("blue") == "blue");
  CHECK(material_of_mesh("green") == "green");
  GltfLoadOptions opt;
  opt.variant = "purple";
  REQUIRE_THROWS_WITH(write_and_load(w, "novariant", opt),
                      Contains("no variant 'purple'") && Contains("'red', 'blue', 'green'"));
  w.j["meshes"][0]["primitives"][0]["extensions"]["KHR_materials_variants"]["mappings"][0]["material"] = 9;
  opt.variant = "blue";
  REQUIRE_THROWS_WITH(
      write_and_load(w, "badmapping", opt),
      Contains("meshes[0].primitives[0].extensions.KHR_materials_variants.mappings[0].material"));
}

TEST_CASE("KHR_materials_pbrSpecularGlossiness converts to metallic-roughness with a warning",
          "[io][gltf][quick]") {
  GltfWriter w = quad_with_material();
  const char* ext = "KHR_materials_pbrSpecularGlossiness";
  w.j["extensionsUsed"] = {ext};
  // A dielectric: grey diffuse, the dielectric's 0.04 specular: metallic 0, the diffuse is the base.
  w.j["materials"] = {{{"extensions",
                        {{ext,
                          {{"diffuseFactor", {0.5, 0.25, 0.125, 0.8}},
                           {"specularFactor", {0.04, 0.04, 0.04}},
                           {"glossinessFactor", 0.25}}}}}}};
  LoadedScene l = write_and_load(w, "specgloss");
  const Material& d = l.scene.materials.at(0);
  CHECK(d.metallic == Approx(0).margin(1e-6));
  CHECK(d.roughness == Approx(0.75));
  CHECK(d.base_color.x == Approx(0.5).epsilon(1e-4));
  CHECK(d.base_color.z == Approx(0.125).epsilon(1e-4));
  CHECK(d.alpha == Approx(0.8));
  REQUIRE(l.warnings.size() == 1);
  CHECK_THAT(l.warnings[0], Contains("materials[0].extensions.KHR_materials_pbrSpecularGlossiness") &&
                                Contains("converted to metallic-roughness"));
  // A metal: black diffuse, coloured specular: metallic 1, the specular colour is the base.
  w.j["materials"][0]["extensions"][ext] = {
      {"diffuseFactor", {0, 0, 0, 1}}, {"specularFactor", {0.9, 0.6, 0.3}}, {"glossinessFactor", 1.0}};
  l = write_and_load(w, "specgloss_metal");
  const Material& m = l.scene.materials.at(0);
  CHECK(m.metallic == Approx(1).margin(1e-3));
  CHECK(m.roughness == Approx(0).margin(1e-6));
  CHECK(m.base_color.x == Approx(0.9).epsilon(1e-3));
  CHECK(m.base_color.z == Approx(0.3).epsilon(1e-3));
  w.j["materials"][0]["extensions"][ext]["glossinessFactor"] = "glossy";
  REQUIRE_THROWS_WITH(write_and_load(w, "specgloss_bad"), Contains("glossinessFactor") && Contains("number"));
}
