# penumbra.load and penumbra.Scene against the shipped glTF files read with the json module:
# counts, names and factors as the JSON declares them, instances per mesh node, world bounds
# that hold every vertex (decoded from the buffers and placed by the node matrices), the
# loader's options (scene index, flatten, time, pose), and the records' fields.
import math

import numpy as np
import pytest

import penumbra
from conftest import SCENES, accessor_array, quad, read_gltf, world_matrices, write_gltf


def index_count(gltf, mesh):
    return sum(gltf["accessors"][p["indices"]]["count"] for p in gltf["meshes"][mesh]["primitives"])


def test_counts_match_the_json(default_scene):
    gltf = read_gltf(SCENES / "default.gltf")
    info = default_scene.info
    assert info["node_count"] == len(gltf["nodes"])
    assert info["mesh_count"] == len(gltf["meshes"])
    assert info["primitive_count"] == sum(len(m["primitives"]) for m in gltf["meshes"])
    assert info["camera_count"] == len(gltf["cameras"])
    assert info["light_count"] == len(gltf["extensions"]["KHR_lights_punctual"]["lights"])
    assert info["scene_count"] == len(gltf["scenes"]) and info["scene_index"] == gltf["scene"]
    assert info["generator"] == gltf["asset"]["generator"]
    assert info["extensions_used"] == gltf["extensionsUsed"]
    assert default_scene.node_names == [n.get("name", f"nodes[{i}]") for i, n in enumerate(gltf["nodes"])]
    # One stored mesh per primitive, each with the primitive's triangles.
    assert len(default_scene.meshes) == info["primitive_count"]
    assert sum(m.triangle_count for m in default_scene.meshes) == default_scene.stored_triangle_count
    assert default_scene.stored_triangle_count == sum(index_count(gltf, m) for m in range(len(gltf["meshes"]))) // 3


def test_instances_are_the_mesh_nodes(default_scene):
    gltf = read_gltf(SCENES / "default.gltf")
    mesh_nodes = {i: n["mesh"] for i, n in enumerate(gltf["nodes"]) if "mesh" in n}
    instances = default_scene.instances
    assert sorted(inst.node for inst in instances) == sorted(mesh_nodes)
    for inst in instances:
        assert inst.shape == -1
        assert inst.triangle_count == index_count(gltf, mesh_nodes[inst.node]) // 3
        assert inst.triangle_count == default_scene.meshes[inst.mesh].triangle_count
    assert default_scene.triangle_count == sum(index_count(gltf, m) for m in mesh_nodes.values()) // 3


def test_instance_maps_place_the_file_vertices(default_scene):
    gltf = read_gltf(SCENES / "default.gltf")
    world = world_matrices(gltf)
    for inst in default_scene.instances:
        prim = gltf["meshes"][gltf["nodes"][inst.node]["mesh"]]["primitives"][0]
        local = accessor_array(gltf, prim["attributes"]["POSITION"], SCENES)
        expected = (world[inst.node] @ np.c_[local, np.ones(len(local))].T).T[:, :3]
        stored = default_scene.meshes[inst.mesh].positions.astype(np.float64)
        placed = (inst.to_world @ np.c_[stored, np.ones(len(stored))].T).T[:, :3]
        np.testing.assert_allclose(placed, expected, atol=1e-5)


def test_bounds_hold_every_vertex_and_are_tight(default_scene):
    gltf = read_gltf(SCENES / "default.gltf")
    world = world_matrices(gltf)
    points = []
    for n, m in world.items():
        node = gltf["nodes"][n]
        if "mesh" not in node:
            continue
        for prim in gltf["meshes"][node["mesh"]]["primitives"]:
            local = accessor_array(gltf, prim["attributes"]["POSITION"], SCENES)
            points.append((m @ np.c_[local, np.ones(len(local))].T).T[:, :3])
    points = np.concatenate(points)
    lo, hi = (np.array(v) for v in default_scene.bounds)
    eps = 1e-5 * max(1.0, float(np.abs(points).max()))
    assert np.all(points >= lo - eps) and np.all(points <= hi + eps)
    np.testing.assert_allclose(lo, points.min(axis=0), atol=eps)
    np.testing.assert_allclose(hi, points.max(axis=0), atol=eps)


def test_cameras_lights_and_materials_match_the_json(default_scene):
    gltf = read_gltf(SCENES / "default.gltf")
    (cam,) = default_scene.cameras
    spec = gltf["cameras"][0]
    assert cam.name == spec["name"] and cam.projection == spec["type"]
    assert cam.yfov == pytest.approx(spec["perspective"]["yfov"])
    assert cam.aspect == pytest.approx(spec["perspective"]["aspectRatio"])
    assert cam.znear == pytest.approx(spec["perspective"]["znear"])
    assert cam.zfar == pytest.approx(spec["perspective"]["zfar"])
    cam_node = next(n for n in gltf["nodes"] if n.get("camera") == 0)
    m = world_matrices(gltf)[gltf["nodes"].index(cam_node)]
    np.testing.assert_allclose(cam.eye, m[:3, 3], atol=1e-6)
    np.testing.assert_allclose(cam.forward, -m[:3, 2], atol=1e-6)  # glTF cameras look down local -Z
    np.testing.assert_allclose(cam.up, m[:3, 1], atol=1e-6)

    specs = gltf["extensions"]["KHR_lights_punctual"]["lights"]
    assert [l.name for l in default_scene.lights] == [s["name"] for s in specs]
    for light, s in zip(default_scene.lights, specs):
        assert light.type == s["type"]
        assert light.intensity == pytest.approx(s["intensity"])
        np.testing.assert_allclose(light.color, s["color"], rtol=1e-6)
        node = next(n for n in gltf["nodes"] if n.get("extensions", {}).get("KHR_lights_punctual", {}).get(
            "light") == specs.index(s))
        np.testing.assert_allclose(light.position, node["translation"], atol=1e-6)

    assert [x.name for x in default_scene.materials] == [x["name"] for x in gltf["materials"]]
    for mat, spec in zip(default_scene.materials, gltf["materials"]):
        pbr = spec.get("pbrMetallicRoughness", {})
        base = pbr.get("baseColorFactor", [1, 1, 1, 1])
        np.testing.assert_allclose(mat.base_color, base[:3], rtol=1e-6)
        assert mat.alpha == pytest.approx(base[3])
        assert mat.metallic == pytest.approx(pbr.get("metallicFactor", 1))
        assert mat.roughness == pytest.approx(pbr.get("roughnessFactor", 1))
        np.testing.assert_allclose(mat.emissive, spec.get("emissiveFactor", [0, 0, 0]), rtol=1e-6)
        assert mat.alpha_mode == spec.get("alphaMode", "OPAQUE")
        assert mat.double_sided == spec.get("doubleSided", False)


def test_shapes_match_the_extension_nodes():
    scene = penumbra.load(SCENES / "spheres.gltf")
    gltf = read_gltf(SCENES / "spheres.gltf")
    shape_nodes = {i: n["extensions"]["PENUMBRA_shapes"] for i, n in enumerate(gltf["nodes"])
                   if "PENUMBRA_shapes" in n.get("extensions", {})}
    assert sorted(s.node for s in scene.shapes) == sorted(shape_nodes)
    for s in scene.shapes:
        assert s.kind == shape_nodes[s.node]["type"]
        assert s.material == shape_nodes[s.node].get("material", -1)
        assert s.name == gltf["nodes"][s.node]["name"]
    assert sorted(i.node for i in scene.instances if i.shape >= 0) == sorted(shape_nodes)
    assert scene.triangle_count == 0 and scene.bounds is not None


def test_flatten_copies_every_placement(default_scene):
    flat = penumbra.load(SCENES / "default.gltf", flatten=True)
    assert all(i.identity for i in flat.instances)
    assert len(flat.instances) == len(default_scene.instances)
    assert flat.triangle_count == default_scene.triangle_count
    # The floor, ceiling and front wall share one mesh: stored once instanced, three times flat.
    assert flat.stored_triangle_count > default_scene.stored_triangle_count
    np.testing.assert_allclose(flat.bounds, default_scene.bounds, atol=1e-6)


def test_time_and_pose_move_the_camera_as_a_fresh_load():
    moving = penumbra.load(SCENES / "flythrough.gltf", time=0.0, keep_animation=True)
    assert moving.animated and moving.info["animation_count"] == 1
    at5 = penumbra.load(SCENES / "flythrough.gltf", time=5.0)
    assert not np.allclose(moving.cameras[0].eye, at5.cameras[0].eye)
    assert moving.pose(5.0)
    for a, b in zip(moving.cameras, at5.cameras):
        np.testing.assert_allclose(a.eye, b.eye, atol=1e-5)
        np.testing.assert_allclose(a.forward, b.forward, atol=1e-5)
    for a, b in zip(moving.instances, at5.instances):
        np.testing.assert_allclose(a.to_world, b.to_world, atol=1e-5)
    # A scene loaded without a time has nothing to pose.
    assert not penumbra.load(SCENES / "flythrough.gltf").pose(5.0)


def test_scene_index_out_of_range_is_an_input_error():
    with pytest.raises(penumbra.InputError) as e:
        penumbra.load(SCENES / "default.gltf", scene=5)
    assert str(SCENES / "default.gltf") in str(e.value)
    assert e.value.file == str(SCENES / "default.gltf")


def test_unknown_variant_is_an_input_error():
    with pytest.raises(penumbra.InputError, match="variant"):
        penumbra.load(SCENES / "default.gltf", variant="no such variant")


def test_max_memory_refuses_a_scene_over_budget():
    with pytest.raises(penumbra.InputError):
        penumbra.load(SCENES / "default.gltf", max_memory=1024)


def test_a_bare_mesh_scene(tmp_path):
    p, i = quad(-1, 1, -1, 1, 0)
    path = write_gltf(tmp_path / "bare.gltf", [{"mesh": 0}], [(p, i, None)])
    scene = penumbra.load(path)
    assert scene.cameras == [] and scene.lights == [] and scene.materials == []
    (inst,) = scene.instances
    assert inst.node == 0 and inst.identity and scene.meshes[inst.mesh].material == -1
    np.testing.assert_array_equal(scene.meshes[0].indices, i)
    np.testing.assert_array_equal(scene.meshes[0].positions, np.array(p, dtype=np.float32))
    assert scene.bounds == ((-1.0, -1.0, 0.0), (1.0, 1.0, 0.0))
    assert scene.info["generator"] == "tests/python/conftest.py"


def test_infinite_perspective_has_an_infinite_far_plane(tmp_path):
    p, i = quad(-1, 1, -1, 1, 0)
    path = write_gltf(tmp_path / "infinite.gltf", [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 3]}],
                      [(p, i, None)], cameras=[{"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1}}])
    (cam,) = penumbra.load(path).cameras
    assert math.isinf(cam.zfar) and cam.znear == pytest.approx(0.1) and cam.aspect == 0
    assert cam.eye == (0.0, 0.0, 3.0) and cam.forward == (0.0, 0.0, -1.0)
