# Scene.proxies on the shipped default scene: every kind holds every world-space vertex of its
# node (read from the glTF with NumPy, independently of the module); Welzl's sphere is no larger
# than Ritter's, the OBB no larger than the AABB, the 6-DOP is the AABB (of a node that is not
# flat) and the hull's volume is Qhull's; a subtree's proxy holds its nodes; the answers equal `penumbra proxies --json`'s; and
# bad kinds, nodes and parameters raise ValueError.
import base64
import json
import struct
import subprocess

import numpy as np
import pytest

import penumbra
from conftest import SCENES, accessor_array, read_gltf, world_matrices

KINDS = ["sphere", "ritter", "aabb", "obb", "capsule", "hull", "kdop", "composite"]


@pytest.fixture(scope="module")
def node_vertices():
    """{node: world-space vertices of its mesh} for the default scene."""
    path = SCENES / "default.gltf"
    gltf = read_gltf(path)
    out = {}
    for n, m in world_matrices(gltf).items():
        node = gltf["nodes"][n]
        if "mesh" not in node:
            continue
        rows = []
        for prim in gltf["meshes"][node["mesh"]]["primitives"]:
            p = accessor_array(gltf, prim["attributes"]["POSITION"], path.parent)
            rows.append(p @ m[:3, :3].T + m[:3, 3])
        out[n] = np.concatenate(rows)
    return out


def contains(proxy, points, tol=1e-5):
    if "radius" in proxy and "center" in proxy:
        return np.all(np.linalg.norm(points - proxy["center"], axis=1) <= proxy["radius"] + tol)
    if "axes" in proxy:
        local = (points - proxy["center"]) @ proxy["axes"].T
        return np.all(np.abs(local) <= proxy["half_extents"] + tol)
    if "a" in proxy:
        a, b = proxy["a"], proxy["b"]
        ab = b - a
        t = np.clip((points - a) @ ab / max(ab @ ab, 1e-300), 0, 1)
        return np.all(np.linalg.norm(points - (a + t[:, None] * ab), axis=1) <= proxy["radius"] + tol)
    inside = np.zeros(len(points), dtype=bool)
    for part in proxy["parts"]:
        pl = part["planes"]
        inside |= np.all(points @ pl[:, :3].T - pl[:, 3] <= tol, axis=1)
    return np.all(inside)


@pytest.mark.parametrize("kind", KINDS)
def test_every_kind_holds_its_node(default_scene, node_vertices, kind):
    proxies = default_scene.proxies(kind, samples=500)
    assert sorted(p["node"] for p in proxies) == sorted(node_vertices)
    for p in proxies:
        assert p["kind"] == kind
        assert contains(p, node_vertices[p["node"]]), f"{kind} of node {p['node']}"
        # A flat node (the floor) has a box of no volume; hulls and k-DOPs give it a thin slab.
        assert p["volume"] >= 0 and p["samples"] == 500 and p["hausdorff"] >= 0
        if kind not in ("aabb", "obb"):
            assert p["volume"] > 0


def test_orderings_and_closed_forms(default_scene):
    by = {k: {p["node"]: p for p in default_scene.proxies(k, samples=0)} for k in KINDS}
    six = {p["node"]: p for p in default_scene.proxies("kdop", kdop=6, samples=0)}
    for node in by["sphere"]:
        assert by["sphere"][node]["radius"] <= by["ritter"][node]["radius"] * (1 + 1e-12)
        assert by["obb"][node]["volume"] <= by["aabb"][node]["volume"] * (1 + 1e-12)
        half = by["aabb"][node]["half_extents"]
        if half.min() > 1e-6 * half.max():  # flat boxes: the 6-DOP is a slab 1e-6 of the size thick
            assert six[node]["volume"] == pytest.approx(by["aabb"][node]["volume"], rel=1e-9)
        if not by["hull"][node]["parts"][0]["thickened"]:  # a flat node's slabs differ at their rims
            assert by["hull"][node]["volume"] <= by["kdop"][node]["volume"] * (1 + 1e-12)
        for part in by["hull"][node]["parts"]:  # Qhull measures its joggled hull: thin slabs differ more
            assert part["volume"] == pytest.approx(part["qhull_volume"], rel=1e-5 if part["thickened"] else 1e-9)
        axes = by["obb"][node]["axes"]
        assert np.allclose(axes @ axes.T, np.eye(3), atol=1e-12)


def test_subtree_and_cli_agree(default_scene, node_vertices, cli):
    node = min(node_vertices)
    one = default_scene.proxies("sphere", node, samples=1000)
    assert len(one) == 1 and one[0]["node"] == node
    doc = json.loads(subprocess.run([cli, "proxies", str(SCENES / "default.gltf"), "--kind", "sphere", "--node",
                                     str(node), "--json", "--samples", "1000", "-q"],
                                    check=True, capture_output=True, text=True).stdout)
    want = doc["proxies"][0]
    assert want["sphere"]["radius"] == one[0]["radius"]
    assert want["sphere"]["center"] == list(one[0]["center"])
    assert want["hausdorff"] == one[0]["hausdorff"]
    by_name = default_scene.proxies("sphere", one[0]["name"], samples=0)
    assert by_name[0]["radius"] == one[0]["radius"]


def test_refusals(default_scene):
    with pytest.raises(ValueError, match="not a proxy kind"):
        default_scene.proxies("cube")
    with pytest.raises(ValueError, match="has no node of that name"):
        default_scene.proxies("obb", "no such node")
    with pytest.raises(ValueError, match="nodes \\(0 to"):
        default_scene.proxies("obb", 9999)
    with pytest.raises(ValueError, match="k must be 6, 14, 18 or 26"):
        default_scene.proxies("kdop", kdop=7)
    with pytest.raises(ValueError, match="samples"):
        default_scene.proxies("obb", samples=-1)


def test_collide_equals_the_command(default_scene, cli):
    for proxy in ("mesh", "obb"):
        r = default_scene.collide(proxy=proxy)
        doc = json.loads(subprocess.run([cli, "collide", str(SCENES / "default.gltf"), "--proxy", proxy, "--json", "-q"],
                                        check=True, capture_output=True, text=True).stdout)
        frame = doc["frames"][0]
        assert [(c["a"], c["b"]) for c in r["contacts"]] == [(c["a"], c["b"]) for c in frame["contacts"]]
        for key in ("nodes", "broad_pairs", "family_pairs", "narrow_tests", "triangle_tests"):
            assert r[key] == frame[key]
        assert r["narrow_tests"] + r["family_pairs"] == r["broad_pairs"]
        for c, fc in zip(r["contacts"], frame["contacts"]):
            assert c["a"] < c["b"]
            assert c["depth"] == fc["depth"] and c["depth_error"] == fc["depth_error"]
            if proxy == "obb":
                assert c["depth"] >= 0 and abs(np.linalg.norm(c["direction"]) - 1) < 1e-9
    with pytest.raises(ValueError, match="not mesh or a proxy kind"):
        default_scene.collide(proxy="cube")


def test_volumes_equal_the_command(default_scene, cli):
    """Scene.collide(volumes=True) measures what `penumbra collide --volumes` does; without it the
    volumes are None."""
    r = default_scene.collide(proxy="obb", volumes=True)
    doc = json.loads(subprocess.run([cli, "collide", str(SCENES / "default.gltf"), "--proxy", "obb", "--volumes", "--json",
                                     "-q"], check=True, capture_output=True, text=True).stdout)
    theirs = doc["frames"][0]["contacts"]
    assert len(r["contacts"]) == len(theirs)
    for mine, other in zip(r["contacts"], theirs):
        assert mine["volume"] == other["volume"] and mine["volume_exact"] and mine["volume_error"] == 0
        assert mine["volume"] >= 0
    assert all(c["volume"] is None for c in default_scene.collide(proxy="obb")["contacts"])


def write_tunnel_scene(path):
    """A wall 0.1 thick at x = 0 and a unit cube animated from x = -3 to x = 3 over one second
    while turning a quarter about x."""
    v = [(x, y, z) for z in (-0.5, 0.5) for y in (-0.5, 0.5) for x in (-0.5, 0.5)]
    f = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    idx = [i for q in f for i in (q[0], q[1], q[2], q[0], q[2], q[3])]
    s = 0.5 ** 0.5
    blob = (b"".join(struct.pack("<3f", *p) for p in v) + struct.pack(f"<{len(idx)}I", *idx) +
            struct.pack("<2f", 0, 1) + struct.pack("<6f", -3, 0, 0, 3, 0, 0) + struct.pack("<8f", 0, 0, 0, 1, s, 0, 0, s))
    views = [(0, 96), (96, 144), (240, 8), (248, 24), (272, 32)]
    accessors = [{"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3", "min": [-0.5] * 3, "max": [0.5] * 3},
                 {"bufferView": 1, "componentType": 5125, "count": 36, "type": "SCALAR"},
                 {"bufferView": 2, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
                 {"bufferView": 3, "componentType": 5126, "count": 2, "type": "VEC3"},
                 {"bufferView": 4, "componentType": 5126, "count": 2, "type": "VEC4"}]
    doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
           "nodes": [{"name": "wall", "mesh": 0, "scale": [0.1, 4, 4]}, {"name": "mover", "mesh": 0, "translation": [-3, 0, 0]}],
           "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
           "animations": [{"samplers": [{"input": 2, "output": 3}, {"input": 2, "output": 4}],
                           "channels": [{"sampler": 0, "target": {"node": 1, "path": "translation"}},
                                        {"sampler": 1, "target": {"node": 1, "path": "rotation"}}]}],
           "accessors": accessors,
           "bufferViews": [{"buffer": 0, "byteOffset": o, "byteLength": n} for o, n in views],
           "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}]}
    path.write_text(json.dumps(doc))
    return path


def test_continuous_equals_the_command(cli, tmp_path):
    """Scene.collide(until=) on a cube that turns as it passes through a wall equals `penumbra
    collide --continuous` between the same two frames, on proxies and on meshes, finds the
    analytic time (the cube's x extent does not change as it turns about x: it touches at
    t = 2.45 / 6), and leaves the scene at its pose."""
    path = write_tunnel_scene(tmp_path / "tunnel.gltf")
    scene = penumbra.load(path, time=0.0, keep_animation=True, quiet=True)
    r = scene.collide(proxy="hull", until=1.0)["continuous"]
    doc = json.loads(subprocess.run([cli, "collide", str(path), "--frames", "0-24:24", "--proxy", "hull", "--continuous",
                                     "--json", "-q"], check=True, capture_output=True, text=True).stdout)
    swept = doc["frames"][0]["continuous"]
    assert swept["to_time"] == r["to_time"] == 1.0
    assert r["moving_nodes"] == swept["moving_nodes"] == 1
    for key in ("nodes", "broad_pairs", "family_pairs", "narrow_tests", "advancement_steps"):
        assert r[key] == swept[key]
    assert [(c["a"], c["b"]) for c in r["contacts"]] == [(c["a"], c["b"]) for c in swept["contacts"]] == [(0, 1)]
    assert abs(r["contacts"][0]["time"] - swept["contacts"][0]["time"]) < 1e-12
    assert abs(r["contacts"][0]["time"] - 2.45 / 6) < 1e-4
    assert scene.collide(proxy="hull")["contacts"] == []  # still at time 0
    assert scene.collide(proxy="hull")["continuous"] is None
    # On the meshes: the exact time, as the command finds it.
    m = scene.collide(until=1.0)["continuous"]
    mdoc = json.loads(subprocess.run([cli, "collide", str(path), "--frames", "0-24:24", "--continuous", "--json", "-q"],
                                     check=True, capture_output=True, text=True).stdout)["frames"][0]["continuous"]
    assert [(c["a"], c["b"]) for c in m["contacts"]] == [(c["a"], c["b"]) for c in mdoc["contacts"]] == [(0, 1)]
    assert abs(m["contacts"][0]["time"] - 2.45 / 6) < 1e-9
    assert m["triangle_pairs"] == mdoc["triangle_pairs"] > 0
    with pytest.raises(ValueError, match="keep_animation"):
        penumbra.load(path, quiet=True).collide(proxy="obb", until=1.0)
