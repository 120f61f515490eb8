// Deep images (OpenEXR 2.0 deep data): per pixel, a list of samples sorted front to back, each
// with its colour (premultiplied), alpha, front and back depth and data channels, such that
// compositing the samples in order with "over" gives the flat pixel (Hillman, "The Theory of
// OpenEXR Deep Samples", 2013; Kainz, "Interpreting OpenEXR Deep Pixels", 2013).
#pragma once

// A camera sample records the surfaces it reached (DeepTrace: each Blend layer and the opaque
// surface behind them, with the coverage and the radiance it gives each); a pixel's records are
// merged per surface (same instance, depths within a relative tolerance of each other) into
// clusters, and the clusters become deep samples:
//   cluster k (front to back) with mean coverage W_k and mean premultiplied radiance R_k over
//   the pixel's camera samples, T_k = 1 - sum_{j<k} W_j the coverage the clusters in front leave:
//     A_k = W_k / T_k,   RGB_k = R_k / T_k,   Z_k = ZBack_k = the cluster's nearest depth
// so that flattening (sum_k prod_{j<k} (1 - A_j) RGB_k = sum_k R_k) gives back the flat beauty's
// RGBA exactly. A sample's alpha is its surface's coverage of the pixel part the surfaces in
// front leave uncovered: deep samples carry no sub-pixel position, so two renders whose surfaces
// share a pixel side by side composite as if their coverage were uncorrelated (Hillman 2013,
// section 5).
// Light that reaches the camera from no surface (a visible environment or background) is a
// sample of alpha 0 at Z = ZBack = +inf, behind everything.

#include <cstdint>
#include <vector>

#include "renderer/core/math.h"
#include "renderer/film/film.h"

namespace penumbra {

/// One surface a camera sample reached, as an integrator records it.
struct DeepHit {
  uint32_t key = 0;      ///< the surface: scene instance index + 1; 0 = nothing (the background)
  uint32_t object = 0;   ///< the id channel: the object id of the data AOVs (glTF node + 1)
  float depth = 0;       ///< camera-space depth (along the view axis); +inf for the background
  float weight = 0;      ///< coverage the sample gives it: its alpha x the transmittance in front
  Vec3f radiance;        ///< premultiplied: the radiance it sends to the camera x weight
  Vec3f normal, albedo;  ///< shading normal (world space) and base colour at the hit
};

/// Records of one camera sample: at most kMaxDeepHits (16 Blend layers, the surface behind
/// them and the background). Plain data on the stack: the integrators never allocate.
inline constexpr int kMaxDeepHits = 18;
struct DeepTrace {
  Vec3f eye, forward;  ///< the camera's position and view axis: depth = dot(p - eye, forward)
  int count = 0;
  DeepHit hits[kMaxDeepHits];
  float depth_of(Vec3f p) const { return dot(p - eye, forward); }
  /// Appends `h`; a record beyond the capacity is added to the last one (nothing is lost).
  void add(const DeepHit& h) {
    if (count < kMaxDeepHits) {
      hits[count++] = h;
      return;
    }
    hits[kMaxDeepHits - 1].weight += h.weight;
    hits[kMaxDeepHits - 1].radiance += h.radiance;
  }
};

/// One deep sample as written: the channels of kDeepChannelNames in order.
struct DeepSample {
  float r = 0, g = 0, b = 0, a = 0;
  float z = 0, zback = 0;
  float id = 0;                                    ///< object id (a whole number; 0 = the background)
  float nx = 0, ny = 0, nz = 0;                    ///< mean shading normal, renormalised
  float albedo_r = 0, albedo_g = 0, albedo_b = 0;  ///< mean base colour (not premultiplied)
};
inline constexpr int kDeepChannels = 13;
static_assert(sizeof(DeepSample) == kDeepChannels * sizeof(float), "DeepSample is kDeepChannels floats");
/// The channel names of DeepSample's members, as the EXR stores them.
inline constexpr const char* kDeepChannelNames[kDeepChannels] = {
    "R", "G", "B", "A", "Z", "ZBack", "id", "N.X", "N.Y", "N.Z", "albedo.R", "albedo.G", "albedo.B"};

/// A deep image over a window of the frame (as Film: origin and full size).
struct DeepImage {
  int width = 0, height = 0;
  int origin_x = 0, origin_y = 0;
  int full_width = 0, full_height = 0;
  std::vector<uint32_t> counts;     ///< samples per pixel, row-major
  std::vector<DeepSample> samples;  ///< every pixel's samples, front to back, pixels row-major
};

/// Bytes a deep image of `pixels` pixels and `samples` samples takes in memory.
inline uint64_t deep_image_bytes(uint64_t pixels, uint64_t samples) {
  return pixels * sizeof(uint32_t) + samples * sizeof(DeepSample);
}

/// The flat image of `deep`: each pixel's samples composited front to back with "over"
/// (RGBA, premultiplied). Requires samples sorted front to back within each pixel.
Film flatten_deep(const DeepImage& deep);

/// Whether two deep images cover the same window of the same frame.
bool same_window(const DeepImage& a, const DeepImage& b);

/// Every image's samples together, per pixel sorted front to back by Z (equal depths by id,
/// alpha and colour): the deep merge of separately rendered elements. Of the background samples
/// (Z = +inf: light from no surface) only the first image's is kept, so that elements rendered
/// against the same environment do not add it up. Requires at least one image, all with
/// same_window() and hard-surface samples (Z = ZBack) sorted front to back.
DeepImage merge_deep(const std::vector<const DeepImage*>& images);

/// `src` held out by `matte`, flat (as Nuke's DeepHoldout): per pixel, the part of the flattened
/// merge of the two that `src`'s samples contribute, i.e. each sample's colour and alpha times
/// prod(1 - A) of every sample of either image in front of it (in merge_deep's order). The
/// background belongs to no element: `src`'s is left out. Without backgrounds, src held out by
/// matte plus matte held out by src is the flattened merge. Same requirements as merge_deep.
Film holdout_deep(const DeepImage& src, const DeepImage& matte);

/// The merge of one pixel's camera samples into deep samples, as the header describes it.
/// Reused from pixel to pixel (clear()); allocates only while its buffers grow.
class DeepPixel {
 public:
  void clear() { m_hits.clear(); }
  /// Adds one camera sample's records.
  void add(const DeepTrace& trace);
  /// Appends the pixel's deep samples (front to back) to `out` for `samples` camera samples
  /// (the mean's divisor, >= 1). Records of one key merge front to back while each lies within
  /// `tolerance` x the depth of the one before it (relative; 0: only equal depths), so a surface
  /// seen at a grazing angle stays one sample; the sample's Z and ZBack are its nearest depth.
  /// Returns the number appended.
  uint32_t resolve(uint32_t samples, float tolerance, std::vector<DeepSample>& out);

 private:
  struct Cluster {
    uint32_t key, object;
    float z, z_last;  ///< nearest and farthest depth merged so far
    double weight, rgb[3], normal[3], albedo[3];
  };
  std::vector<DeepHit> m_hits;
  std::vector<Cluster> m_clusters;
};

}  // namespace penumbra
