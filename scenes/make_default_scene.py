#!/usr/bin/env python3
"""Writes scenes/default.gltf: Penumbra's default scene for the course's Whitted ray tracer.

A closed room (white floor and ceiling, red left wall, green right wall, grey back wall) with a
mirror on the back wall, a glossy blue sphere, a polished gold sphere, a matte yellow box turned
by a quaternion, two KHR_lights_punctual point lights (warm and cool) that cast visible shadows,
and a perspective camera. Pure standard library; the output is deterministic, so re-running it
reproduces the committed file byte for byte.

Usage: python3 scenes/make_default_scene.py [OUTPUT]   (default: scenes/default.gltf)
"""
import base64
import json
import math
import os
import struct
import sys


class Builder:
    def __init__(self):
        self.blob = bytearray()
        self.gltf = {
            "asset": {"version": "2.0", "generator": "penumbra scenes/make_default_scene.py"},
            "extensionsUsed": ["KHR_lights_punctual"],
            "scene": 0,
            "scenes": [{"name": "room", "nodes": []}],
            "nodes": [], "meshes": [], "materials": [], "accessors": [], "bufferViews": [],
            "buffers": [], "cameras": [],
            "extensions": {"KHR_lights_punctual": {"lights": []}},
        }

    def _view(self, data, target):
        while len(self.blob) % 4:
            self.blob.append(0)
        offset = len(self.blob)
        self.blob += data
        view = {"buffer": 0, "byteOffset": offset, "byteLength": len(data)}
        if target is not None:
            view["target"] = target
        self.gltf["bufferViews"].append(view)
        return len(self.gltf["bufferViews"]) - 1

    def _accessor(self, view, ctype, count, atype, lo=None, hi=None):
        acc = {"bufferView": view, "componentType": ctype, "count": count, "type": atype}
        if lo is not None:
            acc["min"], acc["max"] = lo, hi
        self.gltf["accessors"].append(acc)
        return len(self.gltf["accessors"]) - 1

    def material(self, name, base, metallic, roughness):
        self.gltf["materials"].append({
            "name": name,
            "pbrMetallicRoughness": {"baseColorFactor": list(base) + [1.0],
                                     "metallicFactor": metallic, "roughnessFactor": roughness}})
        return len(self.gltf["materials"]) - 1

    def mesh(self, name, positions, normals, indices, material):
        pdata = b"".join(struct.pack("<3f", *p) for p in positions)
        ndata = b"".join(struct.pack("<3f", *n) for n in normals)
        idata = b"".join(struct.pack("<H", i) for i in indices)
        lo = [min(p[k] for p in positions) for k in range(3)]
        hi = [max(p[k] for p in positions) for k in range(3)]
        pa = self._accessor(self._view(pdata, 34962), 5126, len(positions), "VEC3", lo, hi)
        na = self._accessor(self._view(ndata, 34962), 5126, len(normals), "VEC3")
        ia = self._accessor(self._view(idata, 34963), 5123, len(indices), "SCALAR")
        self.gltf["meshes"].append({"name": name, "primitives": [
            {"attributes": {"POSITION": pa, "NORMAL": na}, "indices": ia, "material": material}]})
        return len(self.gltf["meshes"]) - 1

    def node(self, name, root=True, **fields):
        self.gltf["nodes"].append(dict(name=name, **fields))
        index = len(self.gltf["nodes"]) - 1
        if root:
            self.gltf["scenes"][0]["nodes"].append(index)
        return index

    def point_light(self, name, color, intensity, position):
        lights = self.gltf["extensions"]["KHR_lights_punctual"]["lights"]
        lights.append({"name": name, "type": "point", "color": color, "intensity": intensity})
        self.node(name, translation=position,
                  extensions={"KHR_lights_punctual": {"light": len(lights) - 1}})

    def finish(self):
        self.gltf["buffers"].append({
            "byteLength": len(self.blob),
            "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(self.blob)).decode()})
        return self.gltf


def quad(width, height):
    """A quad in the XY plane facing +Z, centred at the origin."""
    w, h = width / 2, height / 2
    pos = [(-w, -h, 0), (w, -h, 0), (w, h, 0), (-w, h, 0)]
    return pos, [(0, 0, 1)] * 4, [0, 1, 2, 0, 2, 3]


def box(sx, sy, sz):
    pos, nrm, idx = [], [], []
    faces = [((1, 0, 0), (0, 0, -1), (0, 1, 0)), ((-1, 0, 0), (0, 0, 1), (0, 1, 0)),
             ((0, 1, 0), (1, 0, 0), (0, 0, -1)), ((0, -1, 0), (1, 0, 0), (0, 0, 1)),
             ((0, 0, 1), (1, 0, 0), (0, 1, 0)), ((0, 0, -1), (-1, 0, 0), (0, 1, 0))]
    half = (sx / 2, sy / 2, sz / 2)
    for n, u, v in faces:
        base = len(pos)
        for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            pos.append(tuple((n[k] + a * u[k] + b * v[k]) * half[k] for k in range(3)))
            nrm.append(n)
        idx += [base, base + 1, base + 2, base, base + 2, base + 3]
    return pos, nrm, idx


def sphere(radius, segments=48, rings=24):
    pos, nrm, idx = [], [], []
    for r in range(rings + 1):
        theta = math.pi * r / rings
        for s in range(segments + 1):
            phi = 2 * math.pi * s / segments
            n = (math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi))
            nrm.append(n)
            pos.append(tuple(radius * c for c in n))
    for r in range(rings):
        for s in range(segments):
            a = r * (segments + 1) + s
            b = a + segments + 1
            idx += [a, b, a + 1, a + 1, b, b + 1]
    return pos, nrm, idx


def quat_axis_angle(axis, degrees):
    half = math.radians(degrees) / 2
    n = math.sqrt(sum(c * c for c in axis))
    return [axis[0] / n * math.sin(half), axis[1] / n * math.sin(half),
            axis[2] / n * math.sin(half), math.cos(half)]


def room():
    """The room, its lights and its camera, before the buffer is written (see build())."""
    b = Builder()
    white = b.material("white wall", (0.8, 0.8, 0.8), 0.0, 0.9)
    red = b.material("red wall", (0.75, 0.08, 0.06), 0.0, 0.9)
    green = b.material("green wall", (0.1, 0.6, 0.12), 0.0, 0.9)
    grey = b.material("back wall", (0.55, 0.55, 0.6), 0.0, 0.9)
    mirror = b.material("mirror", (0.95, 0.95, 0.95), 1.0, 0.0)
    blue = b.material("glossy blue plastic", (0.05, 0.2, 0.8), 0.0, 0.25)
    gold = b.material("polished gold", (1.0, 0.78, 0.34), 1.0, 0.15)
    yellow = b.material("matte yellow", (0.85, 0.65, 0.1), 0.0, 1.0)
    frame = b.material("mirror frame", (0.1, 0.08, 0.06), 0.0, 0.6)

    W, H, D = 6.0, 3.5, 6.0  # room width (x), height (y), depth (z); floor at y = 0
    wall = b.mesh("wall", *quad(1.0, 1.0), white)
    for name, mat, t, r, s in [
        ("floor", white, [0, 0, 0], quat_axis_angle((1, 0, 0), -90), [W, D, 1]),
        ("ceiling", white, [0, H, 0], quat_axis_angle((1, 0, 0), 90), [W, D, 1]),
        ("back wall", grey, [0, H / 2, -D / 2], [0, 0, 0, 1], [W, H, 1]),
        ("front wall", white, [0, H / 2, D / 2], quat_axis_angle((0, 1, 0), 180), [W, H, 1]),
        ("left wall", red, [-W / 2, H / 2, 0], quat_axis_angle((0, 1, 0), 90), [D, H, 1]),
        ("right wall", green, [W / 2, H / 2, 0], quat_axis_angle((0, 1, 0), -90), [D, H, 1]),
    ]:
        m = wall if mat == white else b.mesh(name, *quad(1.0, 1.0), mat)
        b.node(name, mesh=m, translation=t, rotation=r, scale=s)

    # Mirror in a dark frame on the back wall (the frame is a child node: hierarchy test).
    frame_node = b.node("mirror frame", mesh=b.mesh("frame", *box(2.6, 1.8, 0.06), frame),
                        translation=[0.4, 1.7, -D / 2 + 0.04])
    b.node("mirror", root=False, mesh=b.mesh("mirror", *quad(2.4, 1.6), mirror),
           translation=[0, 0, 0.035])
    b.gltf["nodes"][frame_node]["children"] = [len(b.gltf["nodes"]) - 1]

    b.node("blue sphere", mesh=b.mesh("sphere", *sphere(0.6), blue), translation=[-1.2, 0.6, -0.6])
    b.node("gold sphere", mesh=b.mesh("gold sphere", *sphere(0.45), gold), translation=[0.9, 0.45, 0.6])
    b.node("yellow box", mesh=b.mesh("box", *box(0.9, 0.9, 0.9), yellow),
           translation=[1.6, 0.45, -1.3], rotation=quat_axis_angle((0, 1, 0), 30))

    b.point_light("warm key", [1.0, 0.85, 0.7], 9.0, [-1.4, 3.0, 1.2])
    b.point_light("cool fill", [0.7, 0.8, 1.0], 5.0, [1.8, 2.9, 0.2])

    b.gltf["cameras"].append({"name": "room camera", "type": "perspective", "perspective": {
        "yfov": 0.95, "aspectRatio": 16 / 9, "znear": 0.05, "zfar": 100.0}})
    b.node("camera", camera=0, translation=[0.0, 1.6, 2.9], rotation=quat_axis_angle((1, 0, 0), -8))
    return b


def build():
    return room().finish()


def write(gltf, name):
    """Writes `gltf` to the path on the command line, else to scenes/NAME, and prints the path."""
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), name)
    with open(out, "w") as f:
        json.dump(gltf, f, indent=1)
        f.write("\n")
    print(out)


def main():
    write(build(), "default.gltf")


if __name__ == "__main__":
    main()
