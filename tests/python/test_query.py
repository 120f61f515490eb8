# Scene.nearest, within, overlap, intersect and pick: against a NumPy oracle that measures every
# triangle of a small scene exactly, against the command's JSON on the shipped scene, against
# the id AOV of a render, across structures and thread counts; and every refusal.
import json
import subprocess

import numpy as np
import pytest

import penumbra
from conftest import SCENES, quad, write_gltf

ACCELS = ["embree", "bvh", "kdtree", "grid", "octree", "bsp", "brute"]


def point_triangle_distance(p, a, b, c):
    """Exact distance from p to triangle abc: the plane inside the triangle, else the nearest edge."""
    n = np.cross(b - a, c - a)
    nn = n @ n
    best = np.inf
    if nn > 0:
        q = p - ((p - a) @ n) / nn * n
        w0, w1, w2 = (np.cross(c - b, q - b) @ n, np.cross(a - c, q - c) @ n, np.cross(b - a, q - a) @ n)
        if w0 >= 0 and w1 >= 0 and w2 >= 0:
            best = np.linalg.norm(p - q)
    for u, v in ((a, b), (b, c), (c, a)):
        d = v - u
        t = 0.0 if d @ d == 0 else np.clip((p - u) @ d / (d @ d), 0, 1)
        best = min(best, np.linalg.norm(p - (u + t * d)))
    return best


@pytest.fixture(scope="module")
def boxes(tmp_path_factory):
    """Three quads and a tilted triangle under translated nodes: (scene, world triangles by (instance, triangle))."""
    q0 = quad(-1, 1, -1, 1, 0)
    q1 = quad(0, 2, 0, 1, -1.5)
    tri = ([[0, 0, 0], [1, 0.5, 0.3], [0.2, 1, -0.4]], [[0, 1, 2]])
    meshes = [(q0[0], q0[1], None), (q1[0], q1[1], None), (tri[0], tri[1], None)]
    nodes = [{"mesh": 0}, {"mesh": 1, "translation": [0.5, 0, 0]}, {"mesh": 2, "translation": [-2, 0.5, 1]},
             {"mesh": 0, "translation": [0, 0, -4]}]
    path = write_gltf(tmp_path_factory.mktemp("q") / "boxes.gltf", nodes, meshes)
    scene = penumbra.load(path)
    tris = {}
    for inst_index, inst in enumerate(scene.instances):
        node = nodes[inst.node]
        positions, indices, _ = meshes[node["mesh"]]
        t = np.array(node.get("translation", [0, 0, 0]), dtype=np.float64)
        for k, (i, j, l) in enumerate(indices):
            tris[inst_index, k] = [np.array(positions[v], dtype=np.float64) + t for v in (i, j, l)]
    return scene, tris


def oracle(tris, p):
    return sorted((point_triangle_distance(p, *abc), key) for key, abc in tris.items())


@pytest.mark.parametrize("accel", ACCELS)
def test_nearest_equals_the_oracle_in_every_structure(boxes, accel):
    scene, tris = boxes
    rng = np.random.default_rng(3)
    points = rng.uniform(-3, 3, size=(40, 3))
    r = scene.nearest(points, k=4, accel=accel)
    assert r["distance"].shape == (40, 4) and r["point"].shape == (40, 4, 3) and r["count"].tolist() == [4] * 40
    for i, p in enumerate(points):
        want = oracle(tris, p)[:4]
        np.testing.assert_allclose(r["distance"][i], [d for d, _ in want], rtol=1e-5, atol=1e-6)
        # The reported point is at the reported distance.
        np.testing.assert_allclose(np.linalg.norm(r["point"][i] - p, axis=1), r["distance"][i], rtol=1e-4, atol=1e-5)
    assert (np.diff(r["distance"], axis=1) >= 0).all()


def test_nearest_is_the_same_in_every_structure_and_thread_count(boxes):
    scene, _ = boxes
    points = np.random.default_rng(4).uniform(-3, 3, size=(200, 3))
    ref = scene.nearest(points, k=3, accel="brute", threads=1)
    for accel in ACCELS[1:]:
        for threads in (1, 2):
            r = scene.nearest(points, k=3, accel=accel, threads=threads)
            for key in ("distance", "instance", "primitive", "node"):
                np.testing.assert_array_equal(r[key], ref[key], err_msg=f"{accel} {key}")


def test_nearest_max_distance_leaves_missing_entries(boxes):
    scene, tris = boxes
    p = np.array([0.0, 0.0, 3.0])
    r = scene.nearest(p, k=8, max_distance=4.0)
    want = [d for d, _ in oracle(tris, p) if d <= 4.0][:8]
    n = int(r["count"][0])
    assert n == len(want) and 0 < n < 8
    assert np.isinf(r["distance"][0, n:]).all() and (r["instance"][0, n:] == -1).all()
    assert np.isnan(r["point"][0, n:]).all()


def test_within_and_overlap_by_ball_equal_the_oracle(boxes):
    scene, tris = boxes
    points = np.array([[0.0, 0.0, 0.5], [0.5, 0.5, -1.0], [5.0, 5.0, 5.0]])
    r = scene.within(points, 1.2, accel="bvh")
    off = r["offsets"]
    assert off.tolist()[0] == 0 and off[-1] == len(r["distance"])
    for i, p in enumerate(points):
        got = list(zip(r["instance"][off[i]:off[i + 1]].tolist(), r["primitive"][off[i]:off[i + 1]].tolist()))
        want = [key for d, key in oracle(tris, p) if d <= 1.2]
        assert sorted(got) == sorted(want)
        ball = scene.overlap(sphere=(*p, 1.2))
        assert ball["instance"].tolist() == r["instance"][off[i]:off[i + 1]].tolist()
    assert off[3] == off[2]  # nothing near (5, 5, 5)


def test_overlap_by_box(boxes):
    scene, tris = boxes
    everything = scene.overlap(box=((-10, -10, -10), (10, 10, 10)))
    assert sorted(zip(everything["instance"].tolist(), everything["primitive"].tolist())) == sorted(tris)
    assert len(scene.overlap(box=(5, 5, 5, 6, 6, 6))["instance"]) == 0
    # A thin slab at z = -4 meets only the last node's quad.
    slab = scene.overlap(box=(-5, -5, -4.01, 5, 5, -3.99))
    assert set(slab["node"].tolist()) == {3}


def test_intersect_hits_the_quads_at_their_depth(boxes):
    scene, _ = boxes
    origins = np.array([[0.0, 0.0, 5.0]])
    dirs = np.array([[0, 0, -1.0], [0.3, 0.2, -5.0], [0, 0, 1.0], [0.6, 0.5, -10.0]])
    r = scene.intersect(origins, dirs)
    assert r["distance"][0] == pytest.approx(5.0) and r["node"][0] == 0
    np.testing.assert_allclose(r["point"][1], [0.3, 0.2, 0.0], atol=1e-5)
    assert np.isinf(r["distance"][2]) and r["instance"][2] == -1
    assert r["point"][3][2] == pytest.approx(0.0, abs=1e-5)
    same = scene.intersect(np.repeat(origins, 4, axis=0), dirs * 3, accel="kdtree", threads=1)
    np.testing.assert_allclose(same["distance"], r["distance"], rtol=1e-5)


def test_nearest_equals_the_command(default_scene, cli, tmp_path):
    points = np.array([[0.3, 1.1, -0.4], [4, 5, 6], [0, 1, 0]])
    np.savetxt(tmp_path / "p.txt", points)
    out = subprocess.run([cli, "query", "nearest", str(SCENES / "default.gltf"), "--points", str(tmp_path / "p.txt"),
                          "--k", "3", "--json", "--accel", "bvh"], capture_output=True, text=True, check=True)
    doc = json.loads(out.stdout)
    r = default_scene.nearest(points, k=3, accel="bvh")
    for i, res in enumerate(doc["results"]):
        assert [m["instance"] for m in res["matches"]] == r["instance"][i].tolist()
        assert [m["node"] for m in res["matches"]] == r["node"][i].tolist()
        np.testing.assert_allclose([m["distance"] for m in res["matches"]], r["distance"][i], rtol=1e-6)


def test_pick_sees_what_the_id_aov_sees(default_scene):
    for kw in ({}, {"accel": "bvh", "width": 48, "height": 27}):
        res = default_scene.render(spp=4, aovs=["id", "Z"], **{"width": 64, "height": 36, **kw})
        obj, mat = res.aovs["object_id"], res.aovs["material_id"]
        h, w = obj.shape
        checked = 0
        for y in range(1, h - 1, 3):
            for x in range(1, w - 1, 3):
                if not ((obj[y - 1:y + 2, x - 1:x + 2] == obj[y, x]).all()
                        and (mat[y - 1:y + 2, x - 1:x + 2] == mat[y, x]).all()):
                    continue
                p = default_scene.pick(x, y, **{"width": 64, "height": 36, **kw})
                if obj[y, x] == 0:
                    assert p is None
                    continue
                assert p["node"] + 1 == obj[y, x] and p["material"] + 1 == mat[y, x]
                assert p["node_name"] == default_scene.node_names[p["node"]]
                checked += 1
        assert checked > 20


def test_pick_takes_render_settings(default_scene):
    settings = penumbra.RenderSettings(width=32, height=18)
    assert default_scene.pick(16, 9, settings) == default_scene.pick(16, 9, width=32, height=18)
    with pytest.raises(ValueError, match=r"pixel \(32, 0\) is outside the 32x18 image"):
        default_scene.pick(32, 0, settings)
    with pytest.raises(TypeError, match="unknown render setting 'colour'"):
        default_scene.pick(0, 0, colour=1)


def test_refusals(default_scene, tmp_path):
    s = default_scene
    with pytest.raises(ValueError, match=r"shape \(N, 3\)"):
        s.nearest(np.zeros((4, 2)))
    with pytest.raises(ValueError, match=r"points\[1\] is not three finite numbers"):
        s.nearest([[0, 0, 0], [np.nan, 0, 0]])
    with pytest.raises(ValueError, match="k must be"):
        s.nearest([0, 0, 0], k=0)
    with pytest.raises(ValueError, match="k must be"):
        s.nearest([0, 0, 0], k=10**6)
    with pytest.raises(ValueError, match="points x k"):
        s.nearest(np.zeros((10**4, 3)), k=65536)
    with pytest.raises(ValueError, match="max_distance"):
        s.nearest([0, 0, 0], max_distance=-1)
    with pytest.raises(ValueError, match="radius"):
        s.within([0, 0, 0], -1)
    with pytest.raises(ValueError, match="max_matches"):
        s.within(np.zeros((50, 3)), 100.0, max_matches=10)
    with pytest.raises(ValueError, match="minimum above its maximum"):
        s.overlap(box=(1, 1, 1, 0, 0, 0))
    with pytest.raises(ValueError, match="give one of box and sphere"):
        s.overlap()
    with pytest.raises(ValueError, match=r"directions\[0\] is zero"):
        s.intersect([0, 0, 0], [0, 0, 0])
    with pytest.raises(ValueError, match="origins must have one row"):
        s.intersect(np.zeros((2, 3)), np.ones((3, 3)))
    with pytest.raises(ValueError):
        s.nearest([0, 0, 0], accel="no-such-structure")
    with pytest.raises(TypeError):
        s.nearest("not points")
    empty = tmp_path / "empty.gltf"
    empty.write_text('{"asset": {"version": "2.0"}, "scenes": [{"nodes": []}], "scene": 0}')
    with pytest.raises(penumbra.InputError, match="holds no geometry to query"):
        penumbra.load(empty).nearest([0, 0, 0])


@pytest.mark.parametrize("accel", ACCELS)
def test_point_sets_answer_the_k_nearest_points_in_every_structure(accel, tmp_path):
    rng = np.random.default_rng(8)
    pts = rng.uniform(-1, 1, size=(2000, 3)).astype(np.float32)
    q = rng.uniform(-1.2, 1.2, size=(50, 3))
    cloud = penumbra.load_points(pts)
    r = cloud.nearest(q, k=6, accel=accel)
    d = np.linalg.norm(pts[None].astype(np.float64) - q.astype(np.float32).astype(np.float64)[:, None], axis=2)
    np.testing.assert_array_equal(r["primitive"], np.argsort(d, axis=1, kind="stable")[:, :6])
    np.testing.assert_allclose(r["distance"], np.sort(d, axis=1)[:, :6], rtol=1e-5)
    np.testing.assert_array_equal(r["point"], pts[r["primitive"]])


def test_point_files_load_as_the_array_does(tmp_path):
    pts = np.random.default_rng(9).uniform(-1, 1, size=(300, 3))
    np.save(tmp_path / "c.npy", pts)
    np.savetxt(tmp_path / "c.txt", pts.astype(np.float32), fmt="%.9g")
    with open(tmp_path / "c.ply", "w") as f:
        f.write(f"ply\nformat ascii 1.0\nelement vertex {len(pts)}\nproperty float x\nproperty float y\n"
                "property float z\nend_header\n")
        np.savetxt(f, pts.astype(np.float32), fmt="%.9g")
    want = penumbra.load_points(pts).nearest([0.1, 0.2, 0.3], k=5)
    for name in ("c.npy", "c.txt", "c.ply"):
        got = penumbra.load_points(tmp_path / name).nearest([0.1, 0.2, 0.3], k=5)
        np.testing.assert_array_equal(got["primitive"], want["primitive"], err_msg=name)
    with pytest.raises(ValueError, match=r"shape \(N, 3\)"):
        penumbra.load_points(np.zeros((3, 2)))
    with pytest.raises(penumbra.InputError, match="300 points exceed the limit of 6 points"):
        penumbra.load_points(tmp_path / "c.npy", max_memory=1000)
    (tmp_path / "bad.npy").write_bytes(b"not numpy")
    with pytest.raises(penumbra.InputError, match="is not a NumPy .npy file"):
        penumbra.load_points(tmp_path / "bad.npy")
