// The PENUMBRA_procedural material extension for the glTF loader: a procedural texture (noise,
// Voronoi or wave pattern with its mapping) driving base colour, roughness, metallic, emission
// strength and a bump, read from the raw JSON and checked against the extension's schema
// (README, "The PENUMBRA_procedural extension"). Internal to io/gltf/.
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "io/gltf/context.h"
#include "renderer/scene/scene.h"

namespace penumbra::gltf {

/// The extension's name on materials and in extensionsUsed / extensionsRequired.
inline constexpr const char* kProceduralExtension = "PENUMBRA_procedural";

/// The schema's names, indexed by the enumerations they name (ProceduralSpace, PatternKind,
/// FractalKind, WorleyFeature, WorleyMetric, VoronoiOutput, WaveType, axis 0-2, WaveProfile,
/// Compose, RampInterpolation); the writer spells values with them.
inline constexpr const char* kSpaces[] = {"object", "world", "uv"};
inline constexpr const char* kPatternTypes[] = {"noise", "voronoi", "wave"};
inline constexpr const char* kFractalKinds[] = {"fbm", "turbulence", "ridged"};
inline constexpr const char* kFeatures[] = {"f1", "f2", "f2-f1"};
inline constexpr const char* kMetrics[] = {"euclidean", "manhattan", "chebyshev"};
inline constexpr const char* kVoronoiOutputs[] = {"distance", "cellRandom"};
inline constexpr const char* kWaveTypes[] = {"bands", "rings"};
inline constexpr const char* kAxes[] = {"x", "y", "z"};
inline constexpr const char* kProfiles[] = {"sine", "saw", "triangle"};
inline constexpr const char* kComposes[] = {"multiply", "replace"};
inline constexpr const char* kInterpolations[] = {"linear", "constant", "smoothstep"};

/// Most colour ramp stops one procedural texture may hold.
inline constexpr int kMaxRampStops = 64;

class JsonReader;

/// The fractal-noise members of `j` (the fractal kind at key `kind_key`, then detail,
/// roughness, lacunarity, distortion, and offset and gain, which apply to the ridged kind only),
/// within the ranges FractalParams documents (distortion in [0, 16], gain in [0, 16]); absent
/// members keep FractalParams' defaults. Shared by PENUMBRA_procedural patterns and
/// PENUMBRA_shapes displacement.
FractalParams read_fractal_params(const JsonReader& reader, const nlohmann::json& j, const std::string& where,
                                  const char* kind_key);

/// One material's procedural texture.
struct MaterialProcedural {
  int material = -1;  ///< index into materials
  ProceduralTexture texture;
};

/// Reads materials[i].extensions.PENUMBRA_procedural of every material of the raw JSON `doc`, in
/// material order, each charged to `budget` before it is stored. Throws InputError(file, JSON path of the
/// offending member, reason naming the material) for anything outside the schema: unknown keys, keys of
/// another pattern type, wrong JSON types, values out of range, unsorted ramps, a singular mapping.
std::vector<MaterialProcedural> read_material_procedurals(const nlohmann::json& doc, const std::string& file,
                                                          MemoryBudget& budget);

/// The extension object describing `tex` (every member, the mapping as a matrix), which
/// read_material_procedurals reads back to the same texture.
nlohmann::json procedural_json(const ProceduralTexture& tex);

/// Moves each texture into scene.procedurals and links it from its material (which must exist).
void attach_procedurals(Scene& scene, std::vector<MaterialProcedural>& procedurals);

}  // namespace penumbra::gltf
