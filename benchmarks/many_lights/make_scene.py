#!/usr/bin/env python3
"""Writes the many-lights benchmark scene: a 16 x 4 x 12 m room lit only by emitters.

About 6,000 small emissive quads (12,000 emissive triangles) of 16 power classes spanning two
decades, in warm and cool colours: strips under the ceiling facing down, sconces on the walls
facing the room, and a swarm of small double-sided tiles floating above the floor; one
emissive-textured panel (a 2 x 1 m sign whose PNG is half black) on the back wall
(KHR_materials_emissive_strength); grey diffuse walls and a few boxes on the floor that cast
shadows; a perspective camera. Deterministic for a seed (its own LCG), pure standard library.

Usage: python3 make_scene.py OUT_DIR [--seed N] [--quads N]
Writes OUT_DIR/many_lights.gltf, many_lights.bin and sign.png; prints the .gltf's path.
"""
import argparse
import json
import math
import os
import struct
import zlib


class Lcg:
    """64-bit LCG (Knuth's MMIX constants); uniform floats from its top 24 bits."""

    def __init__(self, seed):
        self.state = (seed * 2654435761 + 1442695040888963407) % 2**64

    def uniform(self, lo=0.0, hi=1.0):
        self.state = (self.state * 6364136223846793005 + 1442695040888963407) % 2**64
        return lo + (hi - lo) * ((self.state >> 40) / float(1 << 24))


def png(width, height, rows):
    """An 8-bit RGB PNG from rows of bytes."""
    raw = b"".join(b"\x00" + bytes(r) for r in rows)

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


class Scene:
    def __init__(self):
        self.blob = bytearray()
        self.gltf = {
            "asset": {"version": "2.0", "generator": "penumbra benchmarks/many_lights/make_scene.py"},
            "extensionsUsed": ["KHR_materials_emissive_strength"],
            "scene": 0, "scenes": [{"name": "many_lights", "nodes": []}],
            "nodes": [], "meshes": [], "materials": [], "accessors": [], "bufferViews": [],
            "buffers": [], "cameras": [], "textures": [], "images": [], "samplers": [],
        }

    def view(self, data, target):
        while len(self.blob) % 4:
            self.blob.append(0)
        self.gltf["bufferViews"].append({"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data),
                                         "target": target})
        self.blob += data
        return len(self.gltf["bufferViews"]) - 1

    def accessor(self, view, ctype, count, atype, lo=None, hi=None):
        a = {"bufferView": view, "componentType": ctype, "count": count, "type": atype}
        if lo is not None:
            a["min"], a["max"] = lo, hi
        self.gltf["accessors"].append(a)
        return len(self.gltf["accessors"]) - 1

    def material(self, name, base=(0.0, 0.0, 0.0), emissive=None, strength=1.0, double_sided=False, texture=None):
        m = {"name": name, "pbrMetallicRoughness": {"baseColorFactor": list(base) + [1.0], "metallicFactor": 0.0,
                                                    "roughnessFactor": 0.9}}
        if emissive is not None:
            m["emissiveFactor"] = list(emissive)
            if strength != 1.0:
                m["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": strength}}
        if texture is not None:
            m["emissiveTexture"] = {"index": texture}
        if double_sided:
            m["doubleSided"] = True
        self.gltf["materials"].append(m)
        return len(self.gltf["materials"]) - 1

    def mesh(self, name, quads, material, uvs=False):
        """quads: (corner, edge_u, edge_v); the front (counter-clockwise) faces edge_u x edge_v."""
        pos, nrm, tex, idx = [], [], [], []
        for c, eu, ev in quads:
            n = (eu[1] * ev[2] - eu[2] * ev[1], eu[2] * ev[0] - eu[0] * ev[2], eu[0] * ev[1] - eu[1] * ev[0])
            ln = math.sqrt(sum(x * x for x in n))
            n = tuple(x / ln for x in n)
            base = len(pos)
            for a, b in ((0, 0), (1, 0), (1, 1), (0, 1)):
                pos.append(tuple(c[k] + a * eu[k] + b * ev[k] for k in range(3)))
                nrm.append(n)
                tex.append((a, 1 - b))
            idx += [base, base + 1, base + 2, base, base + 2, base + 3]
        pa = self.accessor(self.view(b"".join(struct.pack("<3f", *p) for p in pos), 34962), 5126, len(pos), "VEC3",
                           [min(p[k] for p in pos) for k in range(3)], [max(p[k] for p in pos) for k in range(3)])
        na = self.accessor(self.view(b"".join(struct.pack("<3f", *p) for p in nrm), 34962), 5126, len(nrm), "VEC3")
        ia = self.accessor(self.view(b"".join(struct.pack("<I", i) for i in idx), 34963), 5125, len(idx), "SCALAR")
        attributes = {"POSITION": pa, "NORMAL": na}
        if uvs:
            attributes["TEXCOORD_0"] = self.accessor(
                self.view(b"".join(struct.pack("<2f", *t) for t in tex), 34962), 5126, len(tex), "VEC2")
        self.gltf["meshes"].append({"name": name, "primitives": [
            {"attributes": attributes, "indices": ia, "material": material}]})
        self.gltf["nodes"].append({"name": name, "mesh": len(self.gltf["meshes"]) - 1})
        self.gltf["scenes"][0]["nodes"].append(len(self.gltf["nodes"]) - 1)


def box(lo, hi):
    """The six outward faces of a box as quads."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    dx, dy, dz = x1 - x0, y1 - y0, z1 - z0
    return [((x0, y0, z0), (0, 0, dz), (0, dy, 0)), ((x1, y0, z0), (0, dy, 0), (0, 0, dz)),
            ((x0, y0, z0), (dx, 0, 0), (0, 0, dz)), ((x0, y1, z0), (0, 0, dz), (dx, 0, 0)),
            ((x0, y0, z0), (0, dy, 0), (dx, 0, 0)), ((x0, y0, z1), (dx, 0, 0), (0, dy, 0))]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out_dir")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--quads", type=int, default=6000)
    a = ap.parse_args()
    rng = Lcg(a.seed)
    s = Scene()
    X, Y, Z = 8.0, 4.0, 6.0  # half width, height, half depth
    grey = s.material("walls", base=(0.6, 0.6, 0.6))
    # The room, faces pointing inwards.
    s.mesh("room", [((-X, 0, -Z), (0, 0, 2 * Z), (2 * X, 0, 0)),      # floor, up
                    ((-X, Y, -Z), (2 * X, 0, 0), (0, 0, 2 * Z)),      # ceiling, down
                    ((-X, 0, -Z), (2 * X, 0, 0), (0, Y, 0)),          # back wall, +z
                    ((-X, 0, Z), (0, Y, 0), (2 * X, 0, 0)),           # front wall, -z
                    ((-X, 0, -Z), (0, Y, 0), (0, 0, 2 * Z)),          # left wall, +x
                    ((X, 0, -Z), (0, 0, 2 * Z), (0, Y, 0))], grey)    # right wall, -x
    s.mesh("boxes", sum((box((x - w, 0, z - w), (x + w, h, z + w))
                         for x, z, w, h in ((-4, -2, 0.6, 1.2), (0.5, 1, 0.5, 2.0), (4.5, -3, 0.8, 0.8),
                                            (-2, 3, 0.4, 1.6), (3, 3.5, 0.5, 0.5))), []),
           s.material("boxes", base=(0.7, 0.5, 0.3)))
    # 16 power classes, two decades, alternately warm and cool.
    classes = []
    for c in range(16):
        warm = c % 2 == 0
        strength = 0.04 * 100 ** (c / 15)
        classes.append((s.material("light%02d" % c, emissive=(1.0, 0.75, 0.5) if warm else (0.6, 0.8, 1.0),
                                   strength=strength), []))
        classes.append((s.material("tile%02d" % c, emissive=(1.0, 0.9, 0.8), strength=strength, double_sided=True), []))
    for i in range(a.quads):
        c = int(rng.uniform(0, 16)) % 16
        kind = rng.uniform()
        size = rng.uniform(0.04, 0.2)
        if kind < 0.4:  # ceiling strips, facing down
            x, z = rng.uniform(-X + 0.2, X - 0.4), rng.uniform(-Z + 0.2, Z - 0.4)
            classes[2 * c][1].append(((x, Y - 0.01, z), (size * 3, 0, 0), (0, 0, size)))
        elif kind < 0.7:  # wall sconces on the left and right walls, facing the room
            side = -1 if rng.uniform() < 0.5 else 1
            y, z = rng.uniform(0.5, Y - 0.5), rng.uniform(-Z + 0.3, Z - 0.3)
            x = side * (X - 0.01)
            eu, ev = ((0, 0, size), (0, size, 0)) if side < 0 else ((0, size, 0), (0, 0, size))
            classes[2 * c][1].append(((x, y, z), eu, ev))
        else:  # floating double-sided tiles, turned about y
            x, y, z = rng.uniform(-X + 1, X - 1), rng.uniform(0.3, Y - 0.5), rng.uniform(-Z + 1, Z - 1)
            t = rng.uniform(0, math.pi)
            classes[2 * c + 1][1].append(((x, y, z), (size * math.cos(t), 0, size * math.sin(t)), (0, size, 0)))
    for mat, quads in classes:
        if quads:
            s.mesh(s.gltf["materials"][mat]["name"], quads, mat)
    # The sign: an emissive texture, half of it black, on the back wall.
    w, h = 64, 32
    rows = [[(255, 200, 80) if (x // 8 + y // 8) % 2 == 0 and x < 48 else (0, 0, 0) for x in range(w)] for y in range(h)]
    with open(os.path.join(a.out_dir, "sign.png"), "wb") as f:
        f.write(png(w, h, [[v for px in r for v in px] for r in rows]))
    s.gltf["images"].append({"uri": "sign.png"})
    s.gltf["samplers"].append({"magFilter": 9728, "minFilter": 9728})
    s.gltf["textures"].append({"source": 0, "sampler": 0})
    sign = s.material("sign", emissive=(1.0, 1.0, 1.0), strength=4.0, texture=0)
    s.mesh("sign", [((-1, 1.5, -Z + 0.01), (2, 0, 0), (0, 1, 0))], sign, uvs=True)
    s.gltf["cameras"].append({"name": "room", "type": "perspective",
                              "perspective": {"yfov": 1.0, "aspectRatio": 16 / 9, "znear": 0.05}})
    # At the front wall, 1.7 m up, looking down the room (-z) and slightly down.
    pitch = -0.15
    s.gltf["nodes"].append({"name": "camera", "camera": 0, "translation": [0.0, 1.7, Z - 0.3],
                            "rotation": [math.sin(pitch / 2), 0.0, 0.0, math.cos(pitch / 2)]})
    s.gltf["scenes"][0]["nodes"].append(len(s.gltf["nodes"]) - 1)
    with open(os.path.join(a.out_dir, "many_lights.bin"), "wb") as f:
        f.write(s.blob)
    s.gltf["buffers"].append({"uri": "many_lights.bin", "byteLength": len(s.blob)})
    path = os.path.join(a.out_dir, "many_lights.gltf")
    with open(path, "w") as f:
        json.dump(s.gltf, f)
    print(path)


if __name__ == "__main__":
    main()
