# Shared fixtures of the Python module's tests: the source tree, the `penumbra` command the
# messages are compared with, the glTF files read as JSON with their vertex data, and a
# builder for tiny scenes whose renders have analytic answers.
# Run by ctest (python.pytest) with PYTHONPATH at the built module and PENUMBRA_CLI at the
# command; by hand: PYTHONPATH=build/python /usr/bin/python3 -m pytest -q tests/python
import base64
import json
import os
import pathlib
import struct

import numpy as np
import pytest

import penumbra

SOURCE_DIR = pathlib.Path(os.environ.get("PENUMBRA_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
SCENES = SOURCE_DIR / "scenes"


@pytest.fixture(scope="session")
def cli():
    """The `penumbra` command built beside the module."""
    path = pathlib.Path(os.environ.get("PENUMBRA_CLI", SOURCE_DIR / "build" / "apps" / "penumbra"))
    if not path.exists():
        pytest.fail(f"the penumbra command is not built at {path} (set PENUMBRA_CLI)")
    return str(path.resolve())


@pytest.fixture(scope="session")
def default_scene():
    return penumbra.load(SCENES / "default.gltf")


def read_gltf(path):
    return json.loads(pathlib.Path(path).read_text())


def buffer_bytes(gltf, index, folder):
    uri = gltf["buffers"][index]["uri"]
    if uri.startswith("data:"):
        return base64.b64decode(uri.split(",", 1)[1])
    return (pathlib.Path(folder) / uri).read_bytes()


_COMPONENTS = {5126: ("f", 4), 5125: ("I", 4), 5123: ("H", 2), 5121: ("B", 1)}
_WIDTHS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}


def accessor_array(gltf, index, folder):
    """A glTF accessor as a (count, width) NumPy array, read with struct from its buffer."""
    acc = gltf["accessors"][index]
    view = gltf["bufferViews"][acc["bufferView"]]
    data = buffer_bytes(gltf, view["buffer"], folder)
    fmt, size = _COMPONENTS[acc["componentType"]]
    width = _WIDTHS[acc["type"]]
    stride = view.get("byteStride", size * width)
    start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
    rows = [struct.unpack_from("<" + fmt * width, data, start + i * stride) for i in range(acc["count"])]
    return np.array(rows, dtype=np.float64)


def node_matrix(node):
    """A glTF node's local matrix (column vectors) from matrix or TRS."""
    if "matrix" in node:
        return np.array(node["matrix"], dtype=np.float64).reshape(4, 4).T
    t = np.array(node.get("translation", [0, 0, 0]), dtype=np.float64)
    x, y, z, w = node.get("rotation", [0, 0, 0, 1])
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    s = np.array(node.get("scale", [1, 1, 1]), dtype=np.float64)
    m = np.eye(4)
    m[:3, :3] = r * s
    m[:3, 3] = t
    return m


def world_matrices(gltf):
    """Every node of the default scene reached from its roots: {node index: world matrix}."""
    scene = gltf["scenes"][gltf.get("scene", 0)]
    out = {}

    def visit(n, parent):
        m = parent @ node_matrix(gltf["nodes"][n])
        out[n] = m
        for c in gltf["nodes"][n].get("children", []):
            visit(c, m)

    for root in scene["nodes"]:
        visit(root, np.eye(4))
    return out


def write_gltf(path, nodes, meshes, materials=(), cameras=(), lights=()):
    """Writes a glTF whose meshes are given as (positions, indices, material) lists; returns the path.

    nodes are glTF node dicts; a mesh's positions are (n, 3) floats and indices (m, 3) ints.
    """
    blob = bytearray()
    views, accessors, gltf_meshes = [], [], []
    for positions, indices, material in meshes:
        p = np.asarray(positions, dtype=np.float32)
        i = np.asarray(indices, dtype=np.uint32)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": p.nbytes})
        accessors.append({"bufferView": len(views) - 1, "componentType": 5126, "count": len(p), "type": "VEC3",
                          "min": p.min(axis=0).tolist(), "max": p.max(axis=0).tolist()})
        blob += p.tobytes()
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": i.nbytes})
        accessors.append({"bufferView": len(views) - 1, "componentType": 5125, "count": i.size, "type": "SCALAR"})
        blob += i.tobytes()
        prim = {"attributes": {"POSITION": len(accessors) - 2}, "indices": len(accessors) - 1}
        if material is not None:
            prim["material"] = material
        gltf_meshes.append({"primitives": [prim]})
    gltf = {
        "asset": {"version": "2.0", "generator": "tests/python/conftest.py"},
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": list(nodes),
        "meshes": gltf_meshes,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode()}],
    }
    if materials:
        gltf["materials"] = list(materials)
    if cameras:
        gltf["cameras"] = list(cameras)
    if lights:
        gltf["extensionsUsed"] = ["KHR_lights_punctual"]
        gltf["extensions"] = {"KHR_lights_punctual": {"lights": list(lights)}}
    pathlib.Path(path).write_text(json.dumps(gltf))
    return path


def quad(x0, x1, y0, y1, z):
    """Two counter-clockwise triangles (front facing +Z) covering [x0, x1] x [y0, y1] at depth z."""
    return [[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]], [[0, 1, 2], [0, 2, 3]]
