// Materials for the glTF loader: metallic-roughness factors and textures (glTF 2.0 spec 3.9),
// texture infos with KHR_texture_transform, and every KHR material extension this loader reads
// (emissive_strength, unlit, ior, specular, transmission). Adding one means touching
// materials.cpp, material_extensions() and materials_test.cpp.
#pragma once

#include <string>
#include <vector>

#include "io/gltf/context.h"
#include "io/gltf/images.h"

namespace penumbra::gltf {

/// The material and texture-info extensions implemented here, in supported_gltf_extensions() order.
std::vector<std::string> material_extensions();

/// Warns about material texture indices out of range (those textures are ignored).
void validate_material_textures(const GltfContext& ctx);

/// Converts every glTF material into ctx.out.scene.materials (same indices), making the textures
/// they use. Throws InputError naming the material field for non-finite or out-of-range values.
void convert_materials(const GltfContext& ctx, TextureCache& cache);

}  // namespace penumbra::gltf
