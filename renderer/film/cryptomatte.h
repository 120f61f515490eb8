// Cryptomatte ID mattes (Friedman and Jones, "Fully Automatic ID Mattes with Support for Motion
// Blur and Transparency", SIGGRAPH 2015 poster; Psyop Cryptomatte specification 1.2.0): names
// hashed with MurmurHash3_x86_32 (Appleby 2011, seed 0), the hash stored bit for bit as a float
// with its exponent clamped to [1, 254], and a ranking pixel filter that keeps, per pixel, the
// ids of the most-covering names with their coverage, highest first. The integrators' AOV pass
// (renderer/integrators/aov.h) fills a CryptoImage from the camera samples.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace penumbra {

/// MurmurHash3_x86_32 of `bytes` with `seed`.
uint32_t murmur3_32(std::string_view bytes, uint32_t seed = 0);

/// The specification's uint32_to_float32 conversion: the hash's bits with the exponent field
/// clamped to [1, 254], so the value is a finite, normal (or tiny) float, never 0, inf or NaN.
float crypto_hash_to_float(uint32_t hash);

/// The id a name gets in the image: crypto_hash_to_float(murmur3_32(name)).
float crypto_id(std::string_view name);

/// The manifest's 8 lower-case hex digits: the bits of crypto_id(name).
std::string crypto_hex(float id);

/// The metadata key of a Cryptomatte layer: the first 7 hex digits of murmur3_32(layer).
std::string crypto_key(std::string_view layer);

/// One Cryptomatte type: its layer name ("CryptoObject") and the id each scene instance gets
/// (one float per Scene::instances entry; the background is 0).
struct CryptoLayerIds {
  std::string layer;
  std::vector<float> instance_ids;
};

/// The ranked (id, coverage) pairs of one layer: `channels` floats per pixel (4 x
/// ceil(depth / 2): rank 2k's id and coverage, then rank 2k+1's, per channel group; ranks
/// beyond the pixel's distinct ids, or beyond an odd depth, are 0), pixels row-major over the
/// render window.
struct CryptoImage {
  int width = 0, height = 0, depth = 0, channels = 0;
  std::vector<std::vector<float>> layers;  ///< one per CryptoLayerIds, in the same order
};

/// Ranks up to `depth` ids among `ids` (one per camera sample; 0 = a miss, not ranked) by
/// coverage = count / ids.size(), highest first, ties by the smaller id's bits; writes
/// `channels` floats to `out` (pairs in rank order, zero-padded). `ids` is reordered.
void rank_crypto_ids(std::vector<float>& ids, int depth, int channels, float* out);

}  // namespace penumbra
