// Draco decoding: the stream into counts, a triangle list and converted attribute values.
#include "io/gltf/draco_decode.h"

#include <draco/compression/decode.h>

namespace penumbra::gltf {

namespace {

// glTF componentType codes (glTF 2.0 spec 3.6.2.2).
enum : int { kByte = 5120, kUByte = 5121, kShort = 5122, kUShort = 5123, kUInt = 5125, kFloat = 5126 };

int component_bytes(int type) {
  switch (type) {
    case kByte:
    case kUByte:
      return 1;
    case kShort:
    case kUShort:
      return 2;
    case kUInt:
    case kFloat:
      return 4;
    default:
      return 0;
  }
}

bool convert(const draco::PointAttribute& att, draco::PointIndex p, int type, int components,
             unsigned char* out) {
  const draco::AttributeValueIndex v = att.mapped_index(p);
  const int8_t n = int8_t(components);
  switch (type) {
    case kFloat:
      return att.ConvertValue<float>(v, n, reinterpret_cast<float*>(out));
    case kByte:
      return att.ConvertValue<int8_t>(v, n, reinterpret_cast<int8_t*>(out));
    case kUByte:
      return att.ConvertValue<uint8_t>(v, n, out);
    case kShort:
      return att.ConvertValue<int16_t>(v, n, reinterpret_cast<int16_t*>(out));
    case kUShort:
      return att.ConvertValue<uint16_t>(v, n, reinterpret_cast<uint16_t*>(out));
    case kUInt:
      return att.ConvertValue<uint32_t>(v, n, reinterpret_cast<uint32_t*>(out));
    default:
      return false;
  }
}

}  // namespace

DracoMesh decode_draco(const unsigned char* data, uint64_t bytes, uint64_t expected_points,
                       uint64_t expected_faces, std::vector<DracoAttribute>& attributes) {
  DracoMesh out;
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(data), size_t(bytes));
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok()) {
    out.error = "malformed Draco stream: " + decoded.status().error_msg_string();
    return out;
  }
  const std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();
  if (!mesh) {
    out.error = "the Draco stream holds no mesh";
    return out;
  }
  out.points = mesh->num_points();
  out.faces = mesh->num_faces();
  if (out.points != expected_points || out.faces != expected_faces) return out;
  out.indices.resize(size_t(out.faces) * 3);
  for (draco::FaceIndex f(0); f < mesh->num_faces(); ++f)
    for (int k = 0; k < 3; ++k) out.indices[size_t(f.value()) * 3 + size_t(k)] = mesh->face(f)[k].value();
  for (DracoAttribute& a : attributes) {
    const draco::PointAttribute* att = mesh->GetAttributeByUniqueId(a.id);
    if (!att) {
      out.error = "the Draco stream has no attribute with id " + std::to_string(a.id);
      return out;
    }
    if (att->num_components() != a.components) {
      out.error = "Draco attribute " + std::to_string(a.id) + " has " +
                  std::to_string(att->num_components()) + " components, the accessor " +
                  std::to_string(a.components);
      return out;
    }
    const size_t elem = size_t(component_bytes(a.component_type)) * size_t(a.components);
    if (elem == 0) {
      out.error = "componentType " + std::to_string(a.component_type) + " is not a vertex attribute type";
      return out;
    }
    a.data.assign(elem * size_t(out.points), 0);
    for (draco::PointIndex p(0); p < mesh->num_points(); ++p)
      if (!convert(*att, p, a.component_type, a.components, a.data.data() + size_t(p.value()) * elem)) {
        out.error = "Draco attribute " + std::to_string(a.id) + " cannot be converted to componentType " +
                    std::to_string(a.component_type);
        return out;
      }
  }
  return out;
}

}  // namespace penumbra::gltf
