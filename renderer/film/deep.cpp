// Merging a pixel's camera samples into deep samples.
#include "renderer/film/deep.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace penumbra {

void DeepPixel::add(const DeepTrace& trace) {
  for (int i = 0; i < trace.count; ++i) {
    DeepHit h = trace.hits[i];
    if (h.key == 0 || !(h.depth == h.depth)) {  // the background, or a depth that is no number
      h.key = 0;
      h.object = 0;
      h.depth = kInfinity;
    }
    m_hits.push_back(h);
  }
}

uint32_t DeepPixel::resolve(uint32_t samples, float tolerance, std::vector<DeepSample>& out) {
  // Front to back; equal depths in key order, so the result does not depend on sample order.
  std::stable_sort(m_hits.begin(), m_hits.end(), [](const DeepHit& a, const DeepHit& b) {
    return a.depth < b.depth || (a.depth == b.depth && a.key < b.key);
  });
  m_clusters.clear();
  for (const DeepHit& h : m_hits) {
    Cluster* c = nullptr;
    // Only the key's latest cluster can take the record: the older ones end nearer still.
    for (auto it = m_clusters.rbegin(); it != m_clusters.rend(); ++it) {
      if (it->key != h.key) continue;
      if (h.key == 0 || h.depth - it->z_last <= tolerance * std::fabs(it->z_last)) c = &*it;
      break;
    }
    if (!c) {
      m_clusters.push_back(Cluster{h.key, h.object, h.depth, h.depth, 0, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}});
      c = &m_clusters.back();
    }
    c->z_last = h.depth;
    const double w = h.weight;
    c->weight += w;
    for (int k = 0; k < 3; ++k) {
      c->rgb[k] += h.radiance[k];
      c->normal[k] += w * h.normal[k];
      c->albedo[k] += w * h.albedo[k];
    }
  }
  const double inv = 1.0 / double(std::max(samples, 1u));
  double transmittance = 1;  // of the pixel, behind the clusters so far
  uint32_t written = 0;
  for (const Cluster& c : m_clusters) {
    const double w = c.weight * inv;
    const double rgb[3] = {c.rgb[0] * inv, c.rgb[1] * inv, c.rgb[2] * inv};
    if (!(w > 0) && rgb[0] == 0 && rgb[1] == 0 && rgb[2] == 0) continue;
    const double t = std::max(transmittance, 1e-9);
    DeepSample s;
    s.r = float(rgb[0] / t);
    s.g = float(rgb[1] / t);
    s.b = float(rgb[2] / t);
    s.a = float(std::clamp(w / t, 0.0, 1.0));
    s.z = s.zback = c.z;
    s.id = float(c.object);
    if (c.weight > 0) {
      const double n =
          std::sqrt(c.normal[0] * c.normal[0] + c.normal[1] * c.normal[1] + c.normal[2] * c.normal[2]);
      if (n > 0) {
        s.nx = float(c.normal[0] / n);
        s.ny = float(c.normal[1] / n);
        s.nz = float(c.normal[2] / n);
      }
      s.albedo_r = float(c.albedo[0] / c.weight);
      s.albedo_g = float(c.albedo[1] / c.weight);
      s.albedo_b = float(c.albedo[2] / c.weight);
    }
    out.push_back(s);
    ++written;
    transmittance = std::max(0.0, transmittance - w);
  }
  return written;
}

namespace {

/// Offsets of each pixel's first sample (pixels + 1 entries).
std::vector<size_t> sample_offsets(const DeepImage& img) {
  std::vector<size_t> first(img.counts.size() + 1, 0);
  for (size_t i = 0; i < img.counts.size(); ++i) first[i + 1] = first[i] + img.counts[i];
  return first;
}

/// The order of samples of separate images at one pixel: by depth, equal depths by id, alpha
/// and colour, so that merge and holdout order them alike whichever image they come from.
bool deep_before(const DeepSample& a, const DeepSample& b) {
  if (a.z != b.z) return a.z < b.z;
  if (a.id != b.id) return a.id < b.id;
  if (a.a != b.a) return a.a < b.a;
  if (a.r != b.r) return a.r < b.r;
  if (a.g != b.g) return a.g < b.g;
  return a.b < b.b;
}

/// Light from no surface: the sample of alpha 0 at +inf a render's background gives.
bool is_background(const DeepSample& s) {
  return std::isinf(s.z);
}

/// An image with `like`'s window and no samples.
DeepImage empty_like(const DeepImage& like) {
  DeepImage out = like;
  out.counts.assign(like.counts.size(), 0);
  out.samples.clear();
  return out;
}

}  // namespace

Film flatten_deep(const DeepImage& deep) {
  Film f = make_film(deep.width, deep.height);
  f.origin_x = deep.origin_x;
  f.origin_y = deep.origin_y;
  f.full_width = deep.full_width;
  f.full_height = deep.full_height;
  size_t k = 0;
  for (size_t i = 0; i < deep.counts.size(); ++i) {
    double rgba[4] = {0, 0, 0, 0};
    for (uint32_t n = 0; n < deep.counts[i]; ++n, ++k) {
      const DeepSample& s = deep.samples[k];
      const double t = 1 - rgba[3];
      rgba[0] += t * s.r;
      rgba[1] += t * s.g;
      rgba[2] += t * s.b;
      rgba[3] += t * s.a;
    }
    for (int c = 0; c < 4; ++c) f.rgba[i * 4 + size_t(c)] = float(rgba[c]);
  }
  return f;
}

bool same_window(const DeepImage& a, const DeepImage& b) {
  return a.width == b.width && a.height == b.height && a.origin_x == b.origin_x && a.origin_y == b.origin_y &&
         a.full_width == b.full_width && a.full_height == b.full_height && a.counts.size() == b.counts.size();
}

DeepImage merge_deep(const std::vector<const DeepImage*>& images) {
  DeepImage out = empty_like(*images.front());
  std::vector<std::vector<size_t>> first;
  for (const DeepImage* img : images) first.push_back(sample_offsets(*img));
  std::vector<DeepSample> pixel;
  for (size_t i = 0; i < out.counts.size(); ++i) {
    pixel.clear();
    bool background = false;  // one image's background, not the sum of all of them
    for (size_t m = 0; m < images.size(); ++m)
      for (size_t k = first[m][i]; k < first[m][i + 1]; ++k) {
        const DeepSample& s = images[m]->samples[k];
        if (is_background(s) && std::exchange(background, true)) continue;
        pixel.push_back(s);
      }
    std::stable_sort(pixel.begin(), pixel.end(), deep_before);
    out.counts[i] = uint32_t(pixel.size());
    out.samples.insert(out.samples.end(), pixel.begin(), pixel.end());
  }
  return out;
}

Film holdout_deep(const DeepImage& src, const DeepImage& matte) {
  Film f = flatten_deep(empty_like(src));
  const std::vector<size_t> first = sample_offsets(src), matte_first = sample_offsets(matte);
  for (size_t i = 0; i < src.counts.size(); ++i) {
    double rgba[4] = {0, 0, 0, 0}, transmittance = 1;
    size_t m = matte_first[i];
    for (size_t k = first[i]; k < first[i + 1]; ++k) {
      const DeepSample& s = src.samples[k];
      if (is_background(s)) break;  // the background is no element's
      for (; m < matte_first[i + 1] && deep_before(matte.samples[m], s); ++m)
        transmittance *= 1 - double(matte.samples[m].a);
      rgba[0] += transmittance * s.r;
      rgba[1] += transmittance * s.g;
      rgba[2] += transmittance * s.b;
      rgba[3] += transmittance * s.a;
      transmittance *= 1 - double(s.a);
    }
    for (int c = 0; c < 4; ++c) f.rgba[i * 4 + size_t(c)] = float(rgba[c]);
  }
  return f;
}

}  // namespace penumbra
