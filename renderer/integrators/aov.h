// First-hit data AOVs for compositing: albedo, shading normal, camera-space depth, world
// position, UV and object/material ids, taken from the same camera sample positions as the
// beauty of either integrator (whitted: the stratified, filtered positions; path: the first
// dimension of each sample's stream), so every layer lines up with the beauty exactly.
#pragma once

// Per pixel, over the pixel's samples:
//   albedo  mean of the first visible surface's base colour (factor x texture x COLOR_0), 0 for
//           samples that miss: premultiplied by coverage like the beauty;
//   N, P, UV  mean over the samples that hit (unpremultiplied data; N renormalised); 0 if none;
//   Z       the nearest camera-space depth (distance along the view axis, as Nuke's ZDefocus
//           reads it) among the samples that hit; +inf where every sample misses;
//   ids     the id hit by most samples (ties: the smaller id); 0 = background. Object id = glTF
//           node index + 1, material id = material index + 1 (0 = the default material).
// Gaussian splats count where the transmittance through them falls below 1/2 (their median
// splat, visibility.h's SplatLayer): that splat's point and ellipsoid normal, the layer's colour
// as albedo, its node's object id and material id 0.

#include <cstdint>
#include <vector>

#include "renderer/film/cryptomatte.h"
#include "renderer/integrators/render.h"

namespace penumbra {

struct DataAovs {
  int width = 0, height = 0;       ///< of render_window(config); every vector covers that window
  std::vector<float> albedo;       ///< 3 per pixel
  std::vector<float> normal;       ///< 3 per pixel, world space
  std::vector<float> position;     ///< 3 per pixel, world space
  std::vector<float> uv;           ///< 2 per pixel (TEXCOORD_0)
  std::vector<float> depth;        ///< 1 per pixel
  std::vector<float> object_id;    ///< 1 per pixel (integer values)
  std::vector<float> material_id;  ///< 1 per pixel (integer values)
  /// With RenderConfig::halves: 2 x kDenoiseFeatures floats per pixel, albedo, N and Z as above
  /// over the pixel's even-numbered samples, then over its odd-numbered ones, seen through
  /// smooth mirrors and glass (denoise_feature), with the background counted as white albedo:
  /// the denoiser's features; else empty.
  std::vector<float> halves;
};

/// What the denoiser's feature halves record of one camera sample.
struct DenoiseFeature {
  bool hit = false;         ///< false: the sample ends in the background (albedo 0, depth +inf)
  Vec3f albedo, normal;     ///< the surface's, tinted by the smooth surfaces seen it through
  float depth = kInfinity;  ///< camera depth of the first hit plus the distance travelled after it
};

/// The denoiser's features of camera ray `ray`, whose first visible surface is si (values mp,
/// camera depth `depth`): the first surface that is not a smooth mirror (metallic >= 0.9,
/// roughness <= 0.1) or smooth glass (transmission >= 0.9, roughness <= 0.1), followed through
/// up to 4 of them by reflection or refraction, with their base colours multiplied into its
/// albedo (base colour plus emission, so that a light stands apart from a white surface). A
/// reflection of the background keeps the smooth surfaces' colours as albedo, the last one's
/// normal and an infinite depth. A mirror's
/// reflection then brings its own edges to the denoiser, as in production denoisers' guides.
DenoiseFeature denoise_feature(const Scene& scene, const Accelerator& accel, const Ray& ray,
                               const SurfaceInteraction& si, const MaterialPoint& mp, float depth,
                               bool filter);

/// Data AOVs covering `window`, cleared to their background values (0, and +inf for Z), with
/// the halves when `halves` is set.
DataAovs make_data_aovs(const PixelWindow& window, bool halves = false);

/// The per-pixel reduction above, sample by sample: what render_data_aovs and the raster
/// integrator's AOVs share. clear() before each pixel; store() writes pixel i of the AOVs.
class AovPixel {
 public:
  void clear();
  /// A sample (number `s` of the pixel) that sees nothing.
  void add_miss(uint32_t s = 0);
  /// Sample `s` of the pixel, whose first visible surface is si (material values mp) at camera
  /// depth `depth`. `feature`, if given, is what the halves record instead of the first hit's
  /// albedo, normal and depth (denoise_feature).
  void add_hit(const Scene& scene, const SurfaceInteraction& si, const MaterialPoint& mp, float depth,
               uint32_t s = 0, const DenoiseFeature* feature = nullptr);
  /// Sample `s` of the pixel, whose first visible thing is a layer of Gaussian splats standing
  /// for a surface at world point p, normal n, colour `albedo`, camera depth `depth`, glTF node
  /// `node` (object id node + 1; material id 0). The halves record the same.
  void add_splats(Vec3f p, Vec3f n, Vec3f albedo, float depth, int node, uint32_t s = 0);
  /// Writes pixel i; the halves too when aovs.halves is not empty.
  void store(DataAovs& aovs, size_t i, int spp);

 private:
  Vec3f m_albedo, m_normal, m_position;
  Vec2f m_uv;
  int m_hits = 0;
  float m_depth = kInfinity;
  // Per half (even, odd sample numbers): samples, hits, albedo and normal sums, nearest depth.
  int m_half_samples[2] = {0, 0}, m_half_hits[2] = {0, 0};
  Vec3f m_half_albedo[2], m_half_normal[2];
  float m_half_depth[2] = {kInfinity, kInfinity};
  std::vector<uint32_t> m_objects, m_materials;
};

/// Traces the camera samples of `integrator` under `config` (threads, tiles, spp, seed,
/// filter, sampler) and reduces them per pixel as above. Deterministic for any thread count.
DataAovs render_data_aovs(const Scene& scene, const Accelerator& accel, const Camera& camera,
                          const RenderConfig& config, IntegratorType integrator);

/// Cryptomatte: traces the same camera samples and ranks each layer's instance ids per pixel
/// (rank_crypto_ids): a sample's weight goes to the surfaces it sees, split over Blend layers
/// by their alpha (up to 16 layers, in eighths of a sample), and to the layers of Gaussian
/// splats in front of them by their opacity (each layer to its median splat's cloud, else its
/// first's), so the coverage is the pixel filter's weight of each name. Requires 1 <= depth and
/// every layer's instance_ids to cover scene.instances, then scene.splat_instances.
/// Deterministic for any thread count.
CryptoImage render_cryptomatte(const Scene& scene, const Accelerator& accel, const Camera& camera,
                               const RenderConfig& config, IntegratorType integrator,
                               const std::vector<CryptoLayerIds>& layers, int depth);

}  // namespace penumbra
