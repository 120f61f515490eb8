#!/usr/bin/env python3
"""Writes the image-textured twin of a glTF scene whose materials use PENUMBRA_procedural.

Each procedural material loses its extension and gains what an artist would bake it into: a
512 x 512 baseColorTexture (when the procedural drives base colour), a metallicRoughnessTexture
(when it drives roughness or metallic) and a normalTexture (when it has a bump), all trilinear
MIP-mapped PNGs written beside the twin. The twin renders the same geometry with the same lights,
so rendering both measures what the procedural textures cost against image textures.

With --undisplaced, both files also replace every displace CSG node by its child, so that the
comparison is not dominated by sphere tracing the displaced surfaces both scenes share.

Usage: python3 benchmarks/make_textured_twin.py [--undisplaced] SCENE.gltf OUT_DIR
(writes OUT_DIR/procedural.gltf, the scene itself, and OUT_DIR/twin.gltf)
"""
import json
import math
import os
import struct
import sys
import zlib

SIZE = 512


def write_png(path, pixel):
    """An 8-bit RGB PNG of SIZE x SIZE whose pixel (x, y) is pixel(x, y) -> (r, g, b) in [0, 1]."""
    rows = bytearray()
    for y in range(SIZE):
        rows.append(0)  # filter type: none
        for x in range(SIZE):
            rows.extend(max(0, min(255, int(c * 255 + 0.5))) for c in pixel(x, y))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", SIZE, SIZE, 8, 2, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(bytes(rows), 6)))
        f.write(chunk(b"IEND", b""))


def wave(x, y, k):
    return 0.5 + 0.5 * math.sin(2 * math.pi * (k * x / SIZE + 0.3 * math.sin(2 * math.pi * y / SIZE)))


def undisplaced(csg):
    """The CSG tree with every displace node replaced by its child."""
    while csg.get("type") == "displace":
        csg = csg["children"][0]
    if "children" in csg:
        csg = dict(csg, children=[undisplaced(c) for c in csg["children"]])
    return csg


def main():
    args = [a for a in sys.argv[1:] if a != "--undisplaced"]
    if len(args) != 2:
        sys.exit(__doc__)
    scene, out_dir = args
    os.makedirs(out_dir, exist_ok=True)
    with open(scene) as f:
        gltf = json.load(f)
    if "--undisplaced" in sys.argv[1:]:
        for node in gltf.get("nodes", []):
            shape = node.get("extensions", {}).get("PENUMBRA_shapes", {})
            if "csg" in shape:
                shape["csg"] = undisplaced(shape["csg"])
    with open(os.path.join(out_dir, "procedural.gltf"), "w") as f:
        json.dump(gltf, f, indent=1)
    gltf = json.loads(json.dumps(gltf))
    images = {
        "color.png": lambda x, y: (wave(x, y, 6), 0.6 * wave(x, y, 6), 0.3),
        "metal_rough.png": lambda x, y: (0, 0.3 + 0.5 * wave(y, x, 4), 0),
        "normal.png": lambda x, y: (0.5 + 0.2 * math.cos(2 * math.pi * 8 * x / SIZE), 0.5, 0.95),
    }
    for name, pixel in images.items():
        write_png(os.path.join(out_dir, name), pixel)
    gltf["images"] = [{"uri": name} for name in images]
    gltf["samplers"] = [{"magFilter": 9729, "minFilter": 9987}]
    gltf["textures"] = [{"source": i, "sampler": 0} for i in range(len(images))]
    for material in gltf.get("materials", []):
        procedural = material.get("extensions", {}).pop("PENUMBRA_procedural", None)
        if procedural is None:
            continue
        pbr = material.setdefault("pbrMetallicRoughness", {})
        if "baseColor" in procedural:
            pbr["baseColorTexture"] = {"index": 0}
        if "roughness" in procedural or "metallic" in procedural:
            pbr["metallicRoughnessTexture"] = {"index": 1}
        if "bump" in procedural:
            material["normalTexture"] = {"index": 2}
    gltf["extensionsUsed"] = [e for e in gltf.get("extensionsUsed", []) if e != "PENUMBRA_procedural"]
    path = os.path.join(out_dir, "twin.gltf")
    with open(path, "w") as f:
        json.dump(gltf, f, indent=1)
    print(path)


if __name__ == "__main__":
    main()
