// KHR_gaussian_splatting: the Gaussian splats of a POINTS primitive read from its attributes and
// checked as the extension's text states them (unit rotation quaternions, linear non-negative
// scales, opacities in [0, 1], complete spherical-harmonic degrees, known colour spaces).
#pragma once

#include <string>

#include "io/gltf/context.h"
#include "renderer/scene/splats.h"

namespace tinygltf {
struct Primitive;
}

namespace penumbra::gltf {

inline constexpr const char* kGaussianSplatting = "KHR_gaussian_splatting";

/// Whether the primitive carries KHR_gaussian_splatting.
bool has_splats(const tinygltf::Primitive& prim);

/// The splats of primitive `prim` (at `where`, e.g. "meshes[0].primitives[1]") over its `nv`
/// POSITION values `positions` (xyz, in the mesh's space). The mode must be POINTS; ROTATION,
/// SCALE, OPACITY and SH_DEGREE_0_COEF_0 are required; higher degrees need every coefficient
/// of every lower one. Rotations are normalised (quantised ones are never exactly unit; a float
/// one more than 1% off unit length, or zero, is an error); scales must be finite and >= 0,
/// opacities in [0, 1], coefficients finite. An unknown kernel falls back to the ellipse (as
/// the extension asks of renderers), an unknown colour space is an error. Throws InputError
/// naming the extension's property or the accessor and the splat.
SplatCloud read_splats(const GltfContext& ctx, const tinygltf::Primitive& prim, const std::string& where,
                       const std::vector<double>& positions);

}  // namespace penumbra::gltf
