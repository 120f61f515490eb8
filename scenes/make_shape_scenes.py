#!/usr/bin/env python3
"""Writes scenes/csg.gltf, spheres.gltf, procedural.gltf, focus.gltf, motion.gltf and
furnace.gltf: Penumbra's scenes of
PENUMBRA_shapes shapes and PENUMBRA_procedural materials.

csg.gltf: the classic CSG part (a sphere intersected with a cube, minus three orthogonal
cylinders), a smooth union of four spheres (a blob) and a tilted torus, all implicit shapes, on
an analytic ground plane, with two KHR_lights_punctual point lights and a perspective camera.

spheres.gltf: analytic spheres of several materials (plastic, metal, chrome, matte) and a
capsule in a room whose four walls are mirrors (metallic 1, roughness 0, analytic boxes) between
an analytic floor and ceiling, with two point lights and a perspective camera.

procedural.gltf: procedural materials: a marble sphere (sine bands distorted by turbulence), a
wooden block (rings distorted by fBm), a rock (an implicit sphere displaced by fBm, coloured and
bumped by noise) on a floor of square tiles (Chebyshev Worley F2 - F1 through a constant ramp,
grooved grout).

focus.gltf: a depth-of-field study: a diagonal row of spheres receding from the camera over a
tiled floor, small emissive spheres far behind them (highlights that defocus into the aperture's
shape), two point lights and a 50 mm-like camera; scenes/focus-pull.json renders it focused near,
in the middle and far.

furnace.gltf: the white furnace: five white metal spheres of roughness 0.2 to 1.0 and no lights,
to render with --integrator path --env 1: with energy compensation they vanish into the
background, without it the rough ones show as grey discs.

All list PENUMBRA_shapes and PENUMBRA_procedural in extensionsUsed only, so tools that do not know the extension still
load them (as empty nodes, cameras and lights). Pure JSON with no buffers; pure standard library;
the output is deterministic, so re-running reproduces the committed files byte for byte.

Usage: python3 scenes/make_shape_scenes.py [OUTPUT_DIR]   (default: scenes/)
"""
import base64
import json
import math
import os
import struct
import sys


class Builder:
    def __init__(self, scene_name):
        self.gltf = {
            "asset": {"version": "2.0", "generator": "penumbra scenes/make_shape_scenes.py"},
            "extensionsUsed": ["KHR_lights_punctual", "PENUMBRA_shapes"],
            "scene": 0,
            "scenes": [{"name": scene_name, "nodes": []}],
            "nodes": [], "materials": [], "cameras": [],
            "extensions": {"KHR_lights_punctual": {"lights": []}},
        }

    def material(self, name, base, metallic, roughness, procedural=None):
        material = {
            "name": name, "doubleSided": True,
            "pbrMetallicRoughness": {"baseColorFactor": list(base) + [1.0],
                                     "metallicFactor": metallic, "roughnessFactor": roughness}}
        if procedural is not None:
            material["extensions"] = {"PENUMBRA_procedural": procedural}
            if "PENUMBRA_procedural" not in self.gltf["extensionsUsed"]:
                self.gltf["extensionsUsed"].append("PENUMBRA_procedural")
        self.gltf["materials"].append(material)
        return len(self.gltf["materials"]) - 1

    def animate(self, node, path, times, values):
        """A LINEAR channel of animations[0] moving `node`'s `path` through `values` (tuples) at
        `times`, its keys stored in the file's one embedded buffer."""
        def accessor(floats, type_, count, extra):
            data = self.gltf.setdefault("_blob", bytearray())
            view = {"buffer": 0, "byteOffset": len(data), "byteLength": 4 * len(floats)}
            data += struct.pack("<%df" % len(floats), *floats)
            self.gltf.setdefault("bufferViews", []).append(view)
            self.gltf.setdefault("accessors", []).append(dict(
                {"bufferView": len(self.gltf["bufferViews"]) - 1, "componentType": 5126,
                 "count": count, "type": type_}, **extra))
            return len(self.gltf["accessors"]) - 1
        flat = [round(c, 6) for v in values for c in v]
        inputs = accessor(times, "SCALAR", len(times), {"min": [min(times)], "max": [max(times)]})
        outputs = accessor(flat, "VEC%d" % len(values[0]), len(values), {})
        animation = self.gltf.setdefault("animations", [{"channels": [], "samplers": []}])[0]
        animation["samplers"].append({"input": inputs, "output": outputs, "interpolation": "LINEAR"})
        animation["channels"].append({"sampler": len(animation["samplers"]) - 1,
                                      "target": {"node": node, "path": path}})

    def child(self, parent, name, **fields):
        """A node under `parent` (not a root of the scene)."""
        self.gltf["nodes"].append(dict(name=name, **fields))
        index = len(self.gltf["nodes"]) - 1
        self.gltf["nodes"][parent].setdefault("children", []).append(index)
        return index

    def finish(self):
        """The glTF, with the animation keys' buffer embedded as a data URI."""
        blob = self.gltf.pop("_blob", None)
        if blob is not None:
            self.gltf["buffers"] = [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64,"
                                     + base64.b64encode(bytes(blob)).decode()}]
        return self.gltf

    def node(self, name, **fields):
        self.gltf["nodes"].append(dict(name=name, **fields))
        index = len(self.gltf["nodes"]) - 1
        self.gltf["scenes"][0]["nodes"].append(index)
        return index

    def shape(self, name, shape, material, **transform):
        """A node carrying a PENUMBRA_shapes shape (a dict with "type") with `material`."""
        return self.node(name, extensions={"PENUMBRA_shapes": dict(shape, material=material)},
                         **transform)

    def point_light(self, name, color, intensity, position):
        lights = self.gltf["extensions"]["KHR_lights_punctual"]["lights"]
        lights.append({"name": name, "type": "point", "color": color, "intensity": intensity})
        self.node(name, translation=position,
                  extensions={"KHR_lights_punctual": {"light": len(lights) - 1}})

    def camera(self, name, eye, target, yfov):
        self.gltf["cameras"].append({"name": name, "type": "perspective", "perspective": {
            "yfov": yfov, "aspectRatio": 16 / 9, "znear": 0.05, "zfar": 200.0}})
        self.node(name, camera=len(self.gltf["cameras"]) - 1, translation=list(eye),
                  rotation=look_rotation(eye, target))


def rounded(values):
    return [round(v, 9) + 0.0 for v in values]


def quat_axis_angle(axis, degrees):
    half = math.radians(degrees) / 2
    n = math.sqrt(sum(c * c for c in axis))
    return rounded([axis[0] / n * math.sin(half), axis[1] / n * math.sin(half),
                    axis[2] / n * math.sin(half), math.cos(half)])


def quat_multiply(a, b):
    """The Hamilton product a b (x, y, z, w): b's rotation, then a's."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return [aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz]


def look_rotation(eye, target):
    """The unit quaternion turning a glTF camera (looking down -Z, +Y up) towards `target`."""
    f = [t - e for t, e in zip(target, eye)]
    n = math.sqrt(sum(c * c for c in f))
    back = [-c / n for c in f]                             # camera +Z
    right = [back[2], 0.0, -back[0]]                       # up (0, 1, 0) x back
    rn = math.sqrt(sum(c * c for c in right))
    right = [c / rn for c in right]
    up = [back[1] * right[2] - back[2] * right[1], back[2] * right[0] - back[0] * right[2],
          back[0] * right[1] - back[1] * right[0]]
    m = [[right[0], up[0], back[0]], [right[1], up[1], back[1]], [right[2], up[2], back[2]]]
    w = math.sqrt(max(0.0, 1 + m[0][0] + m[1][1] + m[2][2])) / 2
    return rounded([(m[2][1] - m[1][2]) / (4 * w), (m[0][2] - m[2][0]) / (4 * w),
                    (m[1][0] - m[0][1]) / (4 * w), w])


def implicit(csg, **fields):
    return dict({"type": "implicit", "csg": csg}, **fields)


def csg(type_, children=None, **fields):
    node = {"type": type_}
    if children is not None:
        node["children"] = children
    node.update(fields)
    return node


def build_csg():
    b = Builder("csg")
    ground = b.material("ground", (0.55, 0.55, 0.52), 0.0, 0.8)
    red = b.material("red plastic", (0.8, 0.12, 0.08), 0.0, 0.35)
    blue = b.material("glossy blue", (0.1, 0.25, 0.85), 0.0, 0.2)
    gold = b.material("polished gold", (1.0, 0.78, 0.34), 1.0, 0.2)

    b.shape("ground", {"type": "plane", "size": [40, 40]}, ground)
    # The classic CSG part: (cube of edge 2 intersected with a sphere of radius 1.35) minus three
    # cylinders of radius 0.55 along X, Y and Z.
    cylinder = {"radius": 0.55, "height": 3}
    part = csg("subtraction", [
        csg("intersection", [csg("box", size=[2, 2, 2]), csg("sphere", radius=1.35)]),
        csg("cylinder", **cylinder),
        csg("cylinder", rotation=quat_axis_angle((0, 0, 1), 90), **cylinder),
        csg("cylinder", rotation=quat_axis_angle((1, 0, 0), 90), **cylinder),
    ])
    b.shape("csg part", implicit(part), red, translation=[-2.6, 1.0, 0.0],
            rotation=quat_axis_angle((0, 1, 0), 30))
    # A blob: four spheres blended by a smooth union.
    blob = csg("smoothUnion", [
        csg("sphere", radius=0.7),
        csg("sphere", radius=0.5, translation=[0.75, 0.35, 0.1]),
        csg("sphere", radius=0.45, translation=[-0.55, 0.65, 0.3]),
        csg("sphere", radius=0.4, translation=[0.15, 0.95, -0.45]),
    ], radius=0.45)
    b.shape("blob", implicit(blob), blue, translation=[0.0, 0.72, 0.4])
    # A torus standing tilted on the ground.
    torus = csg("torus", majorRadius=0.8, minorRadius=0.28)
    b.shape("torus", implicit(torus), gold, translation=[2.6, 1.0, 0.0],
            rotation=quat_axis_angle((1, 0, 0.3), 70))

    b.point_light("warm key", [1.0, 0.88, 0.75], 80.0, [-3.0, 6.0, 4.5])
    b.point_light("cool fill", [0.7, 0.8, 1.0], 35.0, [4.5, 4.0, 3.0])
    b.camera("csg camera", [0.0, 3.2, 7.5], [0.0, 0.8, 0.0], 0.62)
    return b.gltf


def build_spheres():
    b = Builder("mirror room")
    mirror = b.material("mirror", (0.92, 0.92, 0.92), 1.0, 0.0)
    floor = b.material("floor", (0.7, 0.68, 0.62), 0.0, 0.85)
    ceiling = b.material("ceiling", (0.85, 0.85, 0.85), 0.0, 0.9)
    materials = [
        b.material("red plastic", (0.8, 0.1, 0.08), 0.0, 0.3),
        b.material("gold", (1.0, 0.78, 0.34), 1.0, 0.15),
        b.material("glossy blue", (0.08, 0.2, 0.8), 0.0, 0.2),
        b.material("chrome", (0.95, 0.95, 0.95), 1.0, 0.0),
        b.material("matte green", (0.15, 0.6, 0.2), 0.0, 1.0),
    ]

    W, H, D, T = 8.0, 4.0, 8.0, 0.1  # room width (x), height (y), depth (z), wall thickness
    b.shape("floor", {"type": "plane", "size": [W, D]}, floor)
    b.shape("ceiling", {"type": "plane", "size": [W, D]}, ceiling, translation=[0, H, 0],
            rotation=quat_axis_angle((1, 0, 0), 180))
    for name, size, position in [
        ("back mirror", [W, H, T], [0, H / 2, -D / 2 - T / 2]),
        ("front mirror", [W, H, T], [0, H / 2, D / 2 + T / 2]),
        ("left mirror", [T, H, D], [-W / 2 - T / 2, H / 2, 0]),
        ("right mirror", [T, H, D], [W / 2 + T / 2, H / 2, 0]),
    ]:
        b.shape(name, {"type": "box", "size": size}, mirror, translation=position)

    for k, (radius, x, z) in enumerate([(0.7, -1.8, -0.8), (0.55, -0.2, -1.6), (0.8, 1.6, -0.6),
                                        (0.45, 0.4, 0.5), (0.35, -1.1, 0.9)]):
        b.shape("sphere %d" % k, {"type": "sphere", "radius": radius}, materials[k],
                translation=[x, radius, z])
    b.shape("capsule", {"type": "capsule", "radius": 0.3, "height": 1.2}, materials[1],
            translation=[2.3, 0.9, -2.4], rotation=quat_axis_angle((0, 0, 1), 20))

    b.point_light("key", [1.0, 0.9, 0.8], 16.0, [-1.5, 3.6, 1.5])
    b.point_light("fill", [0.75, 0.85, 1.0], 9.0, [2.0, 3.5, -1.0])
    b.camera("room camera", [0.0, 1.8, 3.6], [0.0, 0.6, -0.8], 0.9)
    return b.gltf


def ramp(*stops):
    return [{"position": p, "color": list(c)} for p, c in stops]


def tile_material(b, base_roughness, scale, grout, grout_width, tile, **channels):
    """Square floor tiles of world-space size 1 / scale: Chebyshev Worley F2 - F1 through a
    constant ramp (grout below grout_width), with further procedural channels as given."""
    return b.material("tiles", (1, 1, 1), 0.0, base_roughness, dict({
        # The floor (y = 0) cuts the cells through their centres (q.y = 0.5), not along a face.
        "space": "world", "scale": scale, "translation": [0, 0.5, 0],
        "pattern": {"type": "voronoi", "feature": "f2-f1", "metric": "chebyshev", "randomness": 0},
        "baseColor": {"ramp": ramp((0.0, grout), (grout_width, tile)),
                      "interpolation": "constant", "compose": "replace"}}, **channels))


def build_procedural():
    b = Builder("procedural")
    tiles = tile_material(b, 1.0, 1.25, (0.16, 0.15, 0.14), 0.07, (0.66, 0.62, 0.55),
                          roughness={"range": [0.95, 0.35], "compose": "replace"}, bump={"height": 0.01})
    marble = b.material("marble", (1, 1, 1), 0.0, 0.25, {
        "space": "object", "scale": 1.3, "rotation": [0, 0, 35],
        "pattern": {"type": "wave", "profile": "sine", "phaseDistortion": 1.6,
                    "fractal": "turbulence", "detail": 6, "roughness": 0.55, "seed": 3},
        "baseColor": {"ramp": ramp((0.0, (0.1, 0.11, 0.12)), (0.3, (0.62, 0.63, 0.62)),
                                   (0.6, (0.9, 0.9, 0.88)), (1.0, (0.96, 0.96, 0.94))),
                      "compose": "replace"},
        "bump": {"height": 0.003}})
    wood = b.material("wood", (1, 1, 1), 0.0, 0.5, {
        "space": "object", "scale": 5.0, "translation": [0.3, 0, 0.2],
        "pattern": {"type": "wave", "wave": "rings", "axis": "y", "profile": "saw",
                    "phaseDistortion": 0.35, "fractal": "fbm", "detail": 3, "seed": 11},
        "baseColor": {"ramp": ramp((0.0, (0.72, 0.47, 0.25)), (0.75, (0.55, 0.33, 0.16)),
                                   (1.0, (0.36, 0.2, 0.09))),
                      "interpolation": "smoothstep", "compose": "replace"},
        "roughness": {"range": [0.45, 0.7], "compose": "replace"}})
    stone = b.material("stone", (1, 1, 1), 0.0, 0.8, {
        "space": "object", "scale": 3.0,
        "pattern": {"type": "noise", "fractal": "fbm", "detail": 5, "roughness": 0.6, "seed": 5},
        "baseColor": {"ramp": ramp((0.2, (0.2, 0.18, 0.16)), (0.5, (0.42, 0.39, 0.35)),
                                   (0.8, (0.6, 0.57, 0.5))),
                      "compose": "replace"},
        "bump": {"height": 0.02}})

    b.shape("floor", {"type": "plane", "size": [30, 30]}, tiles)
    b.shape("marble sphere", {"type": "sphere", "radius": 0.8}, marble, translation=[-2.1, 0.8, 0.0])
    b.shape("wooden block", {"type": "box", "size": [1.4, 1.0, 1.0]}, wood,
            translation=[0.05, 0.5, -0.2], rotation=quat_axis_angle((0, 1, 0), -25))
    rock = csg("displace", [csg("roundBox", size=[1.5, 1.1, 1.3], radius=0.35)],
               amplitude=0.14, frequency=2.2, seed=9, noise="fbm", detail=4, roughness=0.55)
    b.shape("rock", implicit(rock), stone, translation=[2.15, 0.58, 0.2],
            rotation=quat_axis_angle((0, 1, 0), 20))

    b.point_light("key", [1.0, 0.9, 0.8], 60.0, [-3.0, 5.5, 4.0])
    b.point_light("fill", [0.7, 0.8, 1.0], 25.0, [4.0, 3.5, 3.5])
    b.camera("procedural camera", [0.0, 2.3, 6.0], [0.0, 0.55, 0.0], 0.58)
    return b.gltf


def build_focus():
    b = Builder("focus")
    tiles = tile_material(b, 0.6, 2.0, (0.12, 0.11, 0.1), 0.06, (0.7, 0.68, 0.62))
    colours = [(0.8, 0.12, 0.08), (0.9, 0.6, 0.1), (0.2, 0.65, 0.25), (0.1, 0.35, 0.85),
               (0.55, 0.2, 0.75), (0.85, 0.85, 0.85)]
    b.shape("floor", {"type": "plane", "size": [60, 60]}, tiles)
    # Six spheres 2.2 units apart along the view, from 2.5 to 13.5 units from the camera.
    for k, colour in enumerate(colours):
        material = b.material("sphere %d" % k, colour, 0.0, 0.35)
        b.shape("sphere %d" % k, {"type": "sphere", "radius": 0.45}, material,
                translation=[-0.9 + 0.45 * k, 0.45, 1.0 - 2.2 * k])
    glow = b.material("glow", (0.0, 0.0, 0.0), 0.0, 1.0)
    b.gltf["materials"][glow]["emissiveFactor"] = [1.0, 0.85, 0.6]
    b.gltf["materials"][glow]["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": 12.0}}
    b.gltf["extensionsUsed"].append("KHR_materials_emissive_strength")
    for k in range(7):
        b.shape("glow %d" % k, {"type": "sphere", "radius": 0.06}, glow,
                translation=[-3.0 + 1.1 * k, 1.2 + 0.35 * (k % 3), -18.0 - 1.5 * (k % 2)])
    b.point_light("key", [1.0, 0.9, 0.8], 120.0, [-3.0, 6.0, 2.0])
    b.point_light("fill", [0.7, 0.8, 1.0], 60.0, [4.0, 4.0, -6.0])
    b.camera("focus camera", [0.6, 1.1, 4.0], [-0.4, 0.55, -6.0], 0.5)
    return b.gltf


def build_furnace():
    b = Builder("furnace")
    # Five white metal spheres (F0 = 1) of roughness 0.2 to 1.0 in a row, no lights: under a
    # uniform white environment (--env 1) a BSDF that conserves energy leaves them invisible.
    for k in range(5):
        roughness = 0.2 * (k + 1)
        material = b.material("white metal %.1f" % roughness, (1.0, 1.0, 1.0), 1.0, roughness)
        b.shape("sphere %.1f" % roughness, {"type": "sphere", "radius": 0.45}, material,
                translation=[-2.0 + 1.0 * k, 0.0, 0.0])
    b.camera("furnace camera", [0.0, 0.0, 9.0], [0.0, 0.0, 0.0], 0.32)
    return b.gltf


def build_motion():
    b = Builder("motion")
    floor = b.material("floor", (0.6, 0.6, 0.62), 0.0, 0.8)
    blade = b.material("blade", (0.85, 0.25, 0.1), 0.0, 0.4)
    hub = b.material("hub", (0.2, 0.2, 0.22), 1.0, 0.3)
    ball = b.material("ball", (0.1, 0.4, 0.9), 0.0, 0.25)
    b.shape("floor", {"type": "plane", "size": [30, 30]}, floor)
    # A fan turning twice a second about its axis (its local +Y, turned to face the camera), keyed
    # every 90 degrees; three blades, children of its hub, follow it.
    fan = b.shape("fan hub", {"type": "sphere", "radius": 0.2}, hub,
                  translation=[-1.2, 1.6, 0.0], rotation=quat_axis_angle((1, 0, 0), 90))
    for k in range(3):
        arm = b.child(fan, "blade arm %d" % k, rotation=quat_axis_angle((0, 1, 0), 120 * k))
        b.child(arm, "blade %d" % k, translation=[0.0, 0.0, 0.6],
                extensions={"PENUMBRA_shapes": {"type": "box", "size": [0.22, 0.05, 1.1], "material": blade}})
    times = [0.125 * k for k in range(17)]
    b.animate(fan, "rotation", times, [rounded(quat_multiply(quat_axis_angle((1, 0, 0), 90),
                                                             quat_axis_angle((0, 1, 0), 90 * k)))
                                       for k in range(17)])
    # A ball flying across at 12 units per second.
    flight = b.shape("ball", {"type": "sphere", "radius": 0.35}, ball, translation=[-12.0, 0.6, 0.8])
    b.animate(flight, "translation", [0.0, 2.0], [(-12.0, 0.6, 0.8), (12.0, 0.6, 0.8)])
    b.point_light("key", [1.0, 0.92, 0.85], 60.0, [-2.0, 5.0, 4.0])
    b.point_light("fill", [0.7, 0.8, 1.0], 25.0, [3.0, 3.0, 3.0])
    b.camera("motion camera", [0.0, 1.6, 6.0], [0.0, 1.0, 0.0], 0.6)
    return b.finish()


def main():
    out_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    for name, build in [("csg.gltf", build_csg), ("spheres.gltf", build_spheres),
                        ("procedural.gltf", build_procedural), ("focus.gltf", build_focus),
                        ("motion.gltf", build_motion), ("furnace.gltf", build_furnace)]:
        path = os.path.join(out_dir, name)
        with open(path, "w") as f:
            json.dump(build(), f, indent=1)
            f.write("\n")
        print(path)


if __name__ == "__main__":
    main()
