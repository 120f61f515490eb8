#!/usr/bin/env python3
"""Writes scenes/splats.gltf: Gaussian splats (KHR_gaussian_splatting) among meshes, for the
splats guide and the splat tests. A sphere of splats fitted to a sphere of radius 0.7 with a
known colour pattern (splat i on a Fibonacci lattice at direction n_i, its local z along n_i,
flat across the surface, colour 0.5 + 0.5 n_i from every direction: the pattern of
renderer/scene/splats.h's make_splat_sphere), a backdrop of flat splats in a checker of two
colours with a view-dependent tint (degree 1), a mirror sphere and a box (meshes) on a floor,
a camera and a light. Regenerates the file byte for byte: python3 scenes/make_splat_scene.py."""
import base64
import json
import math
import pathlib
import struct

blob = bytearray()
views, accessors = [], []
EXT = "KHR_gaussian_splatting"


def add(values, fmt, count, type_, component=5126, minmax=None):
    """Appends packed values as a buffer view and accessor; returns the accessor index."""
    while len(blob) % 4:
        blob.append(0)
    data = struct.pack("<" + fmt * len(values), *values)
    views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)})
    blob.extend(data)
    acc = {"bufferView": len(views) - 1, "componentType": component, "count": count, "type": type_}
    if minmax:
        acc["min"], acc["max"] = minmax
    accessors.append(acc)
    return len(accessors) - 1


def vec(points, type_="VEC3", bounds=False):
    flat = [round(c, 6) for p in points for c in p]
    n = len(points[0])
    mm = None
    if bounds:
        mm = ([min(p[k] for p in points) for k in range(n)], [max(p[k] for p in points) for k in range(n)])
    return add(flat, "f", len(points), type_, minmax=mm)


def scalars(values):
    return add([round(v, 6) for v in values], "f", len(values), "SCALAR")


def indices(idx):
    return add(idx, "I", len(idx), "SCALAR", component=5125)


meshes, nodes = [], []


def mesh(name, prim, node=None):
    meshes.append({"name": name, "primitives": [prim]})
    n = {"name": name, "mesh": len(meshes) - 1}
    if node:
        n.update(node)
    nodes.append(n)


SH0 = 0.2820947917738781
SH1 = 0.4886025119029199


def splats(name, pos, rot, scale, opacity, sh, node):
    attrs = {"POSITION": vec(pos, bounds=True), f"{EXT}:ROTATION": vec(rot, "VEC4"),
             f"{EXT}:SCALE": vec(scale), f"{EXT}:OPACITY": scalars(opacity)}
    for k, coefs in enumerate(sh):
        degree = 0 if k == 0 else 1
        attrs[f"{EXT}:SH_DEGREE_{degree}_COEF_{k - (0 if k == 0 else 1)}"] = vec(coefs)
    mesh(name, {"attributes": attrs, "mode": 0,
                "extensions": {EXT: {"kernel": "ellipse", "colorSpace": "lin_rec709_display"}}}, node)


# The sphere of splats: 2000 on a Fibonacci lattice, radius 0.7.
N, R = 2000, 0.7
spacing = math.sqrt(4 * math.pi * R * R / N)
pos, rot, scale, sh = [], [], [], []
for i in range(N):
    y = 1 - 2 * (i + 0.5) / N
    r = math.sqrt(max(0.0, 1 - y * y))
    a = math.pi * (3 - math.sqrt(5)) * i
    n = (r * math.cos(a), y, r * math.sin(a))
    pos.append(tuple(R * c for c in n))
    q = (-n[1], n[0], 0.0, 1 + n[2])  # +z to n
    ql = math.sqrt(q[0] ** 2 + q[1] ** 2 + q[3] ** 2)
    rot.append((q[0] / ql, q[1] / ql, 0.0, q[3] / ql) if ql > 1e-6 else (1.0, 0.0, 0.0, 0.0))
    scale.append((0.6 * spacing, 0.6 * spacing, 0.06 * spacing))
    sh.append(tuple(0.5 * c / SH0 for c in n))
splats("splat sphere", pos, rot, scale, [0.95] * N, [sh], {"translation": [0, 0.75, 0]})

# The backdrop: 32 x 16 flat splats in the plane z = 0, a checker of teal and sand, tinted by
# the view direction's x (degree 1, coefficient m = 1 multiplies -0.4886 x).
pos, rot, scale, dc, c1, c2, c3 = [], [], [], [], [], [], []
for j in range(16):
    for i in range(32):
        pos.append((-2.4 + 0.15 * i + 0.075, 0.15 * j + 0.075, 0.0))
        rot.append((0.0, 0.0, 0.0, 1.0))
        scale.append((0.09, 0.09, 0.008))
        col = (0.15, 0.45, 0.5) if ((i // 4) + (j // 4)) % 2 else (0.75, 0.62, 0.4)
        dc.append(tuple((c - 0.5) / SH0 for c in col))
        c1.append((0.0, 0.0, 0.0))
        c2.append((0.0, 0.0, 0.0))
        c3.append((-0.15 / SH1, 0.0, 0.15 / SH1))
splats("splat backdrop", pos, rot, scale, [0.9] * len(pos), [dc, c1, c2, c3], {"translation": [0, 0, -1.6]})

# A mirror sphere (a UV sphere of triangles) and a box, on a floor.
rings, segs = 24, 48
sp, sn = [], []
for a in range(rings + 1):
    th = math.pi * a / rings
    for b in range(segs + 1):
        ph = 2 * math.pi * b / segs
        n = (math.sin(th) * math.cos(ph), math.cos(th), -math.sin(th) * math.sin(ph))
        sn.append(n)
        sp.append(tuple(0.5 * c for c in n))
tris = []
for a in range(rings):
    for b in range(segs):
        k0, k1 = a * (segs + 1) + b, (a + 1) * (segs + 1) + b
        tris += [k0, k1, k0 + 1, k0 + 1, k1, k1 + 1]
mesh("mirror sphere", {"attributes": {"POSITION": vec(sp, bounds=True), "NORMAL": vec(sn)},
                       "indices": indices(tris), "material": 0}, {"translation": [1.35, 0.5, 0.5]})
box = [(x, y, z) for x in (-0.3, 0.3) for y in (0, 0.6) for z in (-0.3, 0.3)]
faces = [0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1, 2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3]
mesh("box", {"attributes": {"POSITION": vec(box, bounds=True)}, "indices": indices(faces), "material": 1},
     {"translation": [-1.4, 0, 0.6], "rotation": [0, 0.3826834, 0, 0.9238795]})
floor = [(-4, 0, -4), (4, 0, -4), (4, 0, 4), (-4, 0, 4)]
mesh("floor", {"attributes": {"POSITION": vec(floor, bounds=True), "NORMAL": vec([(0, 1, 0)] * 4)},
               "indices": indices([0, 2, 1, 0, 3, 2]), "material": 2})
nodes.append({"name": "camera", "camera": 0, "translation": [0, 1.6, 4.6],
              "rotation": [-0.1305262, 0, 0, 0.9914449]})
nodes.append({"name": "key", "translation": [1.5, 4, 3], "extensions": {"KHR_lights_punctual": {"light": 0}}})

gltf = {
    "asset": {"version": "2.0", "generator": "penumbra scenes/make_splat_scene.py"},
    "extensionsUsed": ["KHR_lights_punctual", EXT],
    "scene": 0,
    "scenes": [{"name": "splats and meshes", "nodes": list(range(len(nodes)))}],
    "nodes": nodes,
    "meshes": meshes,
    "materials": [
        {"name": "mirror", "pbrMetallicRoughness": {"baseColorFactor": [0.95, 0.95, 0.95, 1], "metallicFactor": 1,
                                                    "roughnessFactor": 0.02}},
        {"name": "box", "pbrMetallicRoughness": {"baseColorFactor": [0.75, 0.2, 0.15, 1], "metallicFactor": 0,
                                                 "roughnessFactor": 0.5}},
        {"name": "floor", "pbrMetallicRoughness": {"baseColorFactor": [0.45, 0.45, 0.45, 1], "metallicFactor": 0}},
    ],
    "cameras": [{"name": "camera", "type": "perspective", "perspective": {"yfov": 0.75, "znear": 0.05}}],
    "extensions": {"KHR_lights_punctual": {"lights": [
        {"name": "key", "type": "point", "intensity": 70, "color": [1, 0.97, 0.92]}]}},
    "accessors": accessors,
    "bufferViews": views,
    "buffers": [{"byteLength": len(blob),
                 "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode()}],
}
out = pathlib.Path(__file__).resolve().parent / "splats.gltf"
out.write_text(json.dumps(gltf, indent=1) + "\n")
print(out)
