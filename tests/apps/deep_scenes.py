#!/usr/bin/env python3
"""Writes the deep holdout test's scenes into OUTDIR: a.gltf (set A: an opaque red box and a green
Blend pane of alpha 0.5), b.gltf (set B: an opaque blue box and a yellow Blend pane of alpha 0.3)
and ab.gltf (both sets), interleaved in depth so that each set hides parts of the other, with one
camera and one directional light shared by all three.
Usage: deep_scenes.py OUTDIR"""
import base64
import json
import struct
import sys


def box(lo, hi):
    """24 vertices (position, normal) and 36 indices of an axis-aligned box."""
    pos, nrm, idx = [], [], []
    for axis in range(3):
        for side in (0, 1):
            n = [0.0, 0.0, 0.0]
            n[axis] = 1.0 if side else -1.0
            u, v = (axis + 1) % 3, (axis + 2) % 3
            base = len(pos)
            for a, b in ((0, 0), (1, 0), (1, 1), (0, 1)):
                p = [0.0, 0.0, 0.0]
                p[axis] = hi[axis] if side else lo[axis]
                p[u] = hi[u] if a else lo[u]
                p[v] = hi[v] if b else lo[v]
                pos.append(p)
                nrm.append(n)
            quad = [0, 1, 2, 0, 2, 3] if side else [0, 2, 1, 0, 3, 2]
            idx += [base + q for q in quad]
    return pos, nrm, idx


def scene(objects):
    """A glTF of `objects` ((name, lo, hi, rgba, blend) each), the camera and the light."""
    blob, views, accessors, meshes, materials, nodes = b"", [], [], [], [], []
    for name, lo, hi, rgba, blend in objects:
        pos, nrm, idx = box(lo, hi)
        first = len(accessors)
        for data, fmt, kind, target in ((pos, "3f", "VEC3", 34962), (nrm, "3f", "VEC3", 34962),
                                        (idx, "I", "SCALAR", 34963)):
            raw = b"".join(struct.pack("<" + fmt, *(d if isinstance(d, list) else [d])) for d in data)
            views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(raw), "target": target})
            blob += raw + b"\0" * (-len(raw) % 4)
            acc = {"bufferView": len(views) - 1, "componentType": 5126 if fmt == "3f" else 5125,
                   "count": len(data), "type": kind}
            if fmt == "3f" and kind == "VEC3" and len(accessors) == first:
                acc["min"] = [min(p[k] for p in data) for k in range(3)]
                acc["max"] = [max(p[k] for p in data) for k in range(3)]
            accessors.append(acc)
        material = {"name": name, "pbrMetallicRoughness": {"baseColorFactor": rgba, "metallicFactor": 0.0,
                                                           "roughnessFactor": 0.6}, "doubleSided": True}
        if blend:
            material["alphaMode"] = "BLEND"
        materials.append(material)
        meshes.append({"name": name, "primitives": [{"attributes": {"POSITION": first, "NORMAL": first + 1},
                                                     "indices": first + 2, "material": len(materials) - 1}]})
        nodes.append({"name": name, "mesh": len(meshes) - 1})
    nodes.append({"name": "camera", "camera": 0, "translation": [0.4, 0.9, 6.0], "rotation": [-0.0698, 0, 0, 0.9976]})
    nodes.append({"name": "sun", "rotation": [-0.5, 0.2, 0.1, 0.835], "extensions": {"KHR_lights_punctual": {"light": 0}}})
    return {
        "asset": {"version": "2.0", "generator": "penumbra deep_scenes.py"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "directional", "intensity": 3.0}]}},
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1, "aspectRatio": 1.5}}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
    }


SET_A = [("red_box", [-1.6, -1.0, -1.0], [0.2, 0.8, 0.6], [0.8, 0.15, 0.1, 1.0], False),
         ("green_pane", [-0.6, -0.4, 1.4], [1.6, 1.4, 1.5], [0.1, 0.9, 0.2, 0.5], True)]
SET_B = [("blue_box", [-0.4, -1.2, -2.0], [1.8, 0.4, 0.0], [0.1, 0.2, 0.9, 1.0], False),
         ("yellow_pane", [-2.0, 0.2, 0.8], [0.0, 1.2, 0.9], [0.9, 0.8, 0.1, 0.3], True)]

if __name__ == "__main__":
    out = sys.argv[1]
    for name, objects in (("a", SET_A), ("b", SET_B), ("ab", SET_A + SET_B)):
        with open(f"{out}/{name}.gltf", "w") as f:
            json.dump(scene(objects), f)
