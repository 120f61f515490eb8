#!/usr/bin/env python3
"""Writes scenes/curves.gltf: glTF points and lines beside a mesh, for the points, lines and
wireframe guide. A helix (LINE_STRIP) with a colour gradient (COLOR_0), a square (LINE_LOOP),
the edges of a tetrahedron (LINES) sized by the file (PENUMBRA_points), a sphere of points
(POINTS, coloured by height), a box and a floor, a camera and two lights. Regenerates the file
byte for byte: python3 scenes/make_curves_scene.py."""
import base64
import json
import math
import pathlib
import struct

blob = bytearray()
views, accessors = [], []


def add(values, fmt, count, type_, component=5126, target=None, minmax=None):
    """Appends packed values as a buffer view and accessor; returns the accessor index."""
    while len(blob) % 4:
        blob.append(0)
    data = struct.pack("<" + fmt * (len(values)), *values)
    view = {"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)}
    if target:
        view["target"] = target
    views.append(view)
    blob.extend(data)
    acc = {"bufferView": len(views) - 1, "componentType": component, "count": count, "type": type_}
    if minmax:
        acc["min"], acc["max"] = minmax
    accessors.append(acc)
    return len(accessors) - 1


def positions(points):
    flat = [c for p in points for c in p]
    lo = [min(p[k] for p in points) for k in range(3)]
    hi = [max(p[k] for p in points) for k in range(3)]
    return add([round(v, 6) for v in flat], "f", len(points), "VEC3", minmax=(lo, hi))


def colours(cols):
    return add([round(c, 6) for col in cols for c in col], "f", len(cols), "VEC3")


def indices(idx):
    return add(idx, "I", len(idx), "SCALAR", component=5125)


meshes, nodes = [], []


def mesh(name, prim, node=None):
    meshes.append({"name": name, "primitives": [prim]})
    n = {"name": name, "mesh": len(meshes) - 1}
    if node:
        n.update(node)
    nodes.append(n)


# A helix of 160 segments, blue at the bottom to orange at the top (LINE_STRIP, 2 px wide).
helix = [(0.6 * math.cos(0.25 * i), 0.011 * i, 0.6 * math.sin(0.25 * i)) for i in range(161)]
grad = [(0.1 + 0.9 * i / 160, 0.3 + 0.2 * i / 160, 1.0 - 0.9 * i / 160) for i in range(161)]
mesh("helix", {"attributes": {"POSITION": positions(helix), "COLOR_0": colours(grad)}, "mode": 3},
     {"translation": [-1.6, 0, 0]})
# A square (LINE_LOOP) in the default white.
mesh("square", {"attributes": {"POSITION": positions([(-0.6, 0, -0.6), (0.6, 0, -0.6), (0.6, 0, 0.6),
                                                      (-0.6, 0, 0.6)])}, "mode": 2},
     {"translation": [0, 0.01, 1.2]})
# The six edges of a tetrahedron (LINES), 4 cm thick from the file.
tet = [(0, 1.2, 0), (0.6, 0.2, 0.35), (-0.6, 0.2, 0.35), (0, 0.2, -0.7)]
mesh("tetrahedron", {"attributes": {"POSITION": positions(tet)}, "indices": indices([0, 1, 0, 2, 0, 3, 1, 2, 2, 3, 3, 1]),
                     "mode": 1, "material": 2, "extensions": {"PENUMBRA_points": {"width": 0.04}}},
     {"translation": [0, 0, -0.2]})
# A sphere of 400 points on a Fibonacci lattice, coloured by height (POINTS).
pts, cols = [], []
for i in range(400):
    y = 1 - 2 * (i + 0.5) / 400
    r = math.sqrt(1 - y * y)
    a = i * math.pi * (3 - math.sqrt(5))
    pts.append((0.55 * r * math.cos(a), 0.55 * y, 0.55 * r * math.sin(a)))
    cols.append((0.5 + 0.5 * y, 0.2, 0.5 - 0.5 * y))
mesh("point sphere", {"attributes": {"POSITION": positions(pts), "COLOR_0": colours(cols)}, "mode": 0},
     {"translation": [1.6, 0.6, 0]})
# A box (triangles, for the wireframe) and a floor.
box = [(x, y, z) for x in (-0.3, 0.3) for y in (0, 0.6) for z in (-0.3, 0.3)]
faces = [0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1, 2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3]
mesh("box", {"attributes": {"POSITION": positions(box)}, "indices": indices(faces), "material": 0},
     {"translation": [1.3, 0, 1.3], "rotation": [0, 0.3826834, 0, 0.9238795]})
floor = [(-4, 0, -4), (4, 0, -4), (4, 0, 4), (-4, 0, 4)]
mesh("floor", {"attributes": {"POSITION": positions(floor), "NORMAL": add([0, 1, 0] * 4, "f", 4, "VEC3")},
               "indices": indices([0, 2, 1, 0, 3, 2]), "material": 1})
nodes.append({"name": "camera", "camera": 0, "translation": [0, 2.2, 5.2],
              "rotation": [-0.2079117, 0, 0, 0.9781476]})
nodes.append({"name": "key", "translation": [2, 4, 3], "extensions": {"KHR_lights_punctual": {"light": 0}}})
nodes.append({"name": "fill", "translation": [-3, 3, 1], "extensions": {"KHR_lights_punctual": {"light": 1}}})

gltf = {
    "asset": {"version": "2.0", "generator": "penumbra scenes/make_curves_scene.py"},
    "extensionsUsed": ["KHR_lights_punctual", "PENUMBRA_points"],
    "scene": 0,
    "scenes": [{"name": "points and lines", "nodes": list(range(len(nodes)))}],
    "nodes": nodes,
    "meshes": meshes,
    "materials": [
        {"name": "box", "pbrMetallicRoughness": {"baseColorFactor": [0.75, 0.2, 0.15, 1], "metallicFactor": 0,
                                                 "roughnessFactor": 0.5}},
        {"name": "floor", "pbrMetallicRoughness": {"baseColorFactor": [0.45, 0.45, 0.45, 1], "metallicFactor": 0}},
        {"name": "tetrahedron", "pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.8, 0.3, 1], "metallicFactor": 0}},
    ],
    "cameras": [{"name": "camera", "type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.05}}],
    "extensions": {"KHR_lights_punctual": {"lights": [
        {"name": "key", "type": "point", "intensity": 60, "color": [1, 0.95, 0.9]},
        {"name": "fill", "type": "point", "intensity": 20, "color": [0.8, 0.9, 1]}]}},
    "accessors": accessors,
    "bufferViews": views,
    "buffers": [{"byteLength": len(blob),
                 "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode()}],
}
out = pathlib.Path(__file__).resolve().parent / "curves.gltf"
out.write_text(json.dumps(gltf, indent=1) + "\n")
print(out)
