#!/usr/bin/env python3
"""Writes scenes/flythrough.gltf: the default room (make_default_scene.py) with a 10 s animation.

The camera flies once around the room's middle (41 LINEAR keys, one every 0.25 s: it circles at
a radius of 2.2 m, rising and falling by 0.4 m, always looking at the spheres), and the yellow
box turns about its vertical axis (36 degrees a second). At 24 frames a second,
`penumbra render scenes/flythrough.gltf --frames 1-240` renders the whole flight. Pure standard
library; the output is deterministic, so re-running it reproduces the committed file byte for
byte.

Usage: python3 scenes/make_flythrough_scene.py [OUTPUT]   (default: scenes/flythrough.gltf)
"""
import math
import struct

from make_default_scene import quat_axis_angle, room, write

SECONDS = 10.0
TARGET = (0.2, 0.8, -0.4)  # what the camera looks at
RADIUS = 2.2


def normalize(v):
    n = math.sqrt(sum(c * c for c in v))
    return tuple(c / n for c in v)


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def look_at(eye, target):
    """The rotation (x, y, z, w) turning a glTF camera (looking down -Z, +Y up) at `target`."""
    w = normalize(tuple(e - t for e, t in zip(eye, target)))
    u = normalize(cross((0.0, 1.0, 0.0), w))
    v = cross(w, u)
    m = [[u[0], v[0], w[0]], [u[1], v[1], w[1]], [u[2], v[2], w[2]]]  # columns u, v, w
    trace = m[0][0] + m[1][1] + m[2][2]
    if trace > 0:
        s = 2 * math.sqrt(trace + 1)
        return [(m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, s / 4]
    i = max(range(3), key=lambda k: m[k][k])
    j, k = (i + 1) % 3, (i + 2) % 3
    s = 2 * math.sqrt(1 + m[i][i] - m[j][j] - m[k][k])
    q = [0.0, 0.0, 0.0, (m[k][j] - m[j][k]) / s]
    q[i] = s / 4
    q[j] = (m[j][i] + m[i][j]) / s
    q[k] = (m[k][i] + m[i][k]) / s
    return q


def flight(t):
    """The camera's eye at time t: once around the target in SECONDS, rising and falling twice."""
    a = 2 * math.pi * t / SECONDS
    return (TARGET[0] + RADIUS * math.sin(a), 1.4 + 0.4 * math.sin(2 * a), TARGET[2] + RADIUS * math.cos(a))


def add_channel(b, node, path, times, values, width):
    """A LINEAR sampler over `times` and `values` (width floats a key) animating node.path."""
    flat = [c for v in values for c in v]
    ta = b._accessor(b._view(struct.pack("<%df" % len(times), *times), None), 5126, len(times), "SCALAR",
                     [min(times)], [max(times)])
    va = b._accessor(b._view(struct.pack("<%df" % len(flat), *flat), None), 5126, len(values),
                     {3: "VEC3", 4: "VEC4"}[width])
    anim = b.gltf.setdefault("animations", [{"name": "fly-through", "samplers": [], "channels": []}])[0]
    anim["samplers"].append({"input": ta, "output": va, "interpolation": "LINEAR"})
    anim["channels"].append({"sampler": len(anim["samplers"]) - 1, "target": {"node": node, "path": path}})


def build():
    b = room()
    b.gltf["asset"]["generator"] = "penumbra scenes/make_flythrough_scene.py"
    nodes = {n["name"]: i for i, n in enumerate(b.gltf["nodes"])}
    times = [0.25 * k for k in range(int(SECONDS / 0.25) + 1)]
    eyes = [flight(t) for t in times]
    turns = [look_at(e, TARGET) for e in eyes]
    for k in range(1, len(turns)):  # the shorter way between keys
        if sum(p * q for p, q in zip(turns[k - 1], turns[k])) < 0:
            turns[k] = [-c for c in turns[k]]
    add_channel(b, nodes["camera"], "translation", times, eyes, 3)
    add_channel(b, nodes["camera"], "rotation", times, turns, 4)
    box_times = [float(s) for s in range(int(SECONDS) + 1)]
    add_channel(b, nodes["yellow box"], "rotation", box_times,
                [quat_axis_angle((0, 1, 0), 30 + 36 * t) for t in box_times], 4)
    return b.finish()


def main():
    write(build(), "flythrough.gltf")


if __name__ == "__main__":
    main()
