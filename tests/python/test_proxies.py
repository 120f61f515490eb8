# Scene.proxies on the shipped default scene: every kind holds every world-space vertex of its
# node (read from the glTF with NumPy, independently of the module); Welzl's sphere is no larger
# than Ritter's, the OBB no larger than the AABB, the 6-DOP is the AABB (of a node that is not
# flat) and the hull's volume is Qhull's; a subtree's proxy holds its nodes; the answers equal `penumbra proxies --json`'s; and
# bad kinds, nodes and parameters raise ValueError.
import json
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
        for c in r["contacts"]:
            assert c["a"] < c["b"]
            assert (c["depth"] is None) == (proxy == "mesh")
            if proxy == "obb":
                assert c["depth"] >= 0 and abs(np.linalg.norm(c["direction"]) - 1) < 1e-9
    with pytest.raises(ValueError, match="not mesh or a proxy kind"):
        default_scene.collide(proxy="cube")
