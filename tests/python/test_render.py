# Scene.render against analytic answers and against itself: the beauty's shape and dtype, the
# data AOVs of two fronto-parallel quads whose depth, position, normal, albedo and ids are known
# (for every integrator and accelerator), windows equal to slices of the frame, identical images
# for 1 and 2 threads and for concurrent renders, the path tracer's layers, the settings' checks,
# the GIL released while a render runs, and Gaussian splats ray traced against rasterised.
import base64
import json
import math
import pathlib
import shutil
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import penumbra
from conftest import SCENES, quad, read_gltf, write_gltf

W, H = 33, 25
YFOV = 0.8
FRONT_EDGE = 0.3  # the front quad covers x <= 0.3 at z = -1
BACK_COLOR, FRONT_COLOR = (0.2, 0.4, 0.6), (0.9, 0.5, 0.1)


@pytest.fixture(scope="module")
def quads(tmp_path_factory):
    """A camera at z = 1 looking down -Z at a back quad at z = -2 (node 1, depth 3) and, on the
    left, a front quad at z = -1 (node 2, depth 2) up to x = 0.3; no lights."""
    back_p, back_i = quad(-20, 20, -20, 20, -2)
    front_p, front_i = quad(-20, FRONT_EDGE, -20, 20, -1)
    path = write_gltf(
        tmp_path_factory.mktemp("quads") / "quads.gltf",
        nodes=[{"name": "camera", "camera": 0, "translation": [0, 0, 1]},
               {"name": "back", "mesh": 0}, {"name": "front", "mesh": 1}],
        meshes=[(back_p, back_i, 0), (front_p, front_i, 1)],
        materials=[{"name": "back material", "pbrMetallicRoughness": {"baseColorFactor": [*BACK_COLOR, 1],
                                                                      "metallicFactor": 0}},
                   {"name": "front material", "pbrMetallicRoughness": {"baseColorFactor": [*FRONT_COLOR, 1],
                                                                       "metallicFactor": 0}}],
        cameras=[{"name": "cam", "type": "perspective",
                  "perspective": {"yfov": YFOV, "znear": 0.01, "zfar": 100}}])
    return penumbra.load(path)


def column_sides():
    """Columns whose every ray meets the front quad, and columns whose every ray misses it."""
    tan_x = math.tan(YFOV / 2) * W / H
    x_at = lambda raster_x: 2 * (2 * raster_x / W - 1) * tan_x  # x where the ray meets z = -1
    front = [i for i in range(W) if x_at(i + 1) < FRONT_EDGE - 1e-3]
    back = [i for i in range(W) if x_at(i) > FRONT_EDGE + 1e-3]
    assert front and back and len(front) + len(back) >= W - 1
    return front, back


def test_beauty_shape_and_dtype(default_scene):
    r = default_scene.render(width=40, height=24, spp=1)
    assert r.beauty.shape == (24, 40, 4) and r.beauty.dtype == np.float32
    assert r.rgb.shape == (24, 40, 3) and r.rgb.dtype == np.float32
    np.testing.assert_array_equal(r.rgb, r.beauty[..., :3])
    assert np.all(np.isfinite(r.beauty)) and r.beauty[..., :3].max() > 0
    np.testing.assert_array_equal(r.beauty[..., 3], 1)  # the room surrounds the camera
    assert r.stats["samples"] == 40 * 24 * 1 and r.stats["camera_rays"] == 40 * 24
    with pytest.raises(ValueError):
        r.beauty[0, 0, 0] = 1  # a read-only view into the result


def test_size_follows_the_camera_aspect(default_scene):
    r = default_scene.render(width=64, spp=1)
    assert (r.width, r.height) == (64, round(64 / (16 / 9)))
    assert r.camera.name == "room camera" and r.camera_index == 0 and not r.default_light


@pytest.mark.parametrize("integrator", ["whitted", "path", "raster"])
@pytest.mark.parametrize("accel", penumbra.accelerator_names())
def test_data_aovs_of_two_quads_are_analytic(quads, integrator, accel):
    r = quads.render(width=W, height=H, spp=4, integrator=integrator, accel=accel, aovs=["all"])
    assert r.default_light  # no light, no emitter, no environment: the default key light
    a = r.aovs
    front, back = column_sides()
    z, p, n = a["Z"], a["P"], a["N"]
    assert z.shape == (H, W) and p.shape == (H, W, 3) and a["UV"].shape == (H, W, 2)
    assert z[H // 2, W // 2] == pytest.approx(2.0, abs=1e-5)  # the centre sees the front quad
    np.testing.assert_allclose(z[:, front], 2.0, atol=1e-5)
    np.testing.assert_allclose(z[:, back], 3.0, atol=1e-5)
    np.testing.assert_allclose(p[:, front, 2], -1.0, atol=1e-5)
    np.testing.assert_allclose(p[:, back, 2], -2.0, atol=1e-5)
    np.testing.assert_allclose(n.reshape(-1, 3), np.tile([0, 0, 1], (H * W, 1)), atol=1e-5)
    np.testing.assert_allclose(a["albedo"][:, front], np.broadcast_to(FRONT_COLOR, (H, len(front), 3)), atol=1e-6)
    np.testing.assert_allclose(a["albedo"][:, back], np.broadcast_to(BACK_COLOR, (H, len(back), 3)), atol=1e-6)
    # Object id = glTF node index + 1, material id = material index + 1.
    assert a["object_id"].dtype == np.uint32
    assert np.all(a["object_id"][:, front] == 3) and np.all(a["object_id"][:, back] == 2)
    assert np.all(a["material_id"][:, front] == 2) and np.all(a["material_id"][:, back] == 1)
    assert r.id_manifest == {"object": {"2": "back", "3": "front"},
                             "material": {"1": "back material", "2": "front material"}}
    np.testing.assert_array_equal(r.beauty[..., 3], 1)


def test_path_layers(quads):
    r = quads.render(width=W, height=H, spp=8, integrator="path", aovs=["samples", "variance", "light"])
    a = r.aovs
    np.testing.assert_array_equal(a["samples"], 8)
    assert a["variance"].shape == (H, W) and np.all(a["variance"] >= 0)
    groups = ["emission", "diffuse_direct", "diffuse_indirect", "specular_direct", "specular_indirect"]
    total = sum(a[g].astype(np.float64) for g in groups)
    np.testing.assert_allclose(total, r.rgb, rtol=1e-4, atol=1e-6)  # the five groups sum to the beauty
    assert "Z" not in a


@pytest.mark.parametrize("integrator", ["whitted", "path"])
def test_deep_output_has_one_sample_per_surface_and_flattens_to_the_beauty(quads, integrator, tmp_path):
    r = quads.render(width=W, height=H, spp=16, integrator=integrator, deep=True)
    counts = r.deep_samples
    assert counts.shape == (H, W) and counts.dtype == np.uint32
    front, back = column_sides()
    if integrator == "whitted":  # a 1-pixel box filter: away from the edge, one surface, one sample
        np.testing.assert_array_equal(counts[:, front], 1)
        np.testing.assert_array_equal(counts[:, back], 1)
    else:  # the 1.5-pixel Blackman-Harris filter reaches a pixel further
        assert np.count_nonzero(counts == 1) >= (len(front) + len(back) - 2) * H
    assert counts.max() <= 2  # two surfaces at most, however many camera samples
    assert quads.render(width=W, height=H, spp=1).deep_samples is None
    oiiotool = shutil.which("oiiotool")
    if oiiotool is None:
        pytest.skip("oiiotool is not installed")
    r.write_deep_exr(tmp_path / "deep.exr")
    r.write_exr(tmp_path / "flat.exr", half=False)
    subprocess.run([oiiotool, str(tmp_path / "deep.exr"), "--flatten", "-o", str(tmp_path / "flattened.exr")],
                   check=True)
    diff = subprocess.run([oiiotool, str(tmp_path / "flattened.exr"), "--ch", "R,G,B,A", str(tmp_path / "flat.exr"),
                           "--ch", "R,G,B,A", "--fail", "1e-3", "--diff"], capture_output=True, text=True)
    assert diff.returncode == 0, diff.stdout
    with pytest.raises(ValueError, match="deep=True"):
        quads.render(width=8, height=6, spp=1).write_deep_exr(tmp_path / "none.exr")
    with pytest.raises(ValueError, match="deep needs integrator"):
        quads.render(width=8, height=6, integrator="raster", deep=True)


def test_window_is_a_slice_of_the_frame(default_scene):
    full = default_scene.render(width=32, height=18, spp=2, aovs=["Z", "id"])
    part = default_scene.render(width=32, height=18, spp=2, aovs=["Z", "id"], window=(8, 4, 24, 16))
    assert part.beauty.shape == (12, 16, 4) and part.origin == (8, 4) and part.frame_size == (32, 18)
    np.testing.assert_array_equal(part.beauty, full.beauty[4:16, 8:24])
    np.testing.assert_array_equal(part.aovs["Z"], full.aovs["Z"][4:16, 8:24])
    np.testing.assert_array_equal(part.aovs["object_id"], full.aovs["object_id"][4:16, 8:24])


@pytest.mark.parametrize("integrator", ["whitted", "path", "raster"])
def test_one_and_two_threads_give_identical_images(default_scene, integrator):
    one = default_scene.render(width=48, height=27, spp=4, integrator=integrator, threads=1, aovs=["all"])
    two = default_scene.render(width=48, height=27, spp=4, integrator=integrator, threads=2, tile_size=8,
                               aovs=["all"])
    np.testing.assert_array_equal(one.beauty, two.beauty)
    assert one.aovs.keys() == two.aovs.keys()
    for name in one.aovs:
        np.testing.assert_array_equal(one.aovs[name], two.aovs[name], err_msg=name)


@pytest.mark.parametrize("shadows", ["ray", "map", "none"])
def test_raster_preview_shadows(default_scene, shadows):
    r = default_scene.render(width=48, height=27, spp=1, integrator="raster", raster_shadows=shadows)
    lit = default_scene.render(width=48, height=27, spp=1, integrator="raster", raster_shadows="none")
    np.testing.assert_array_equal(r.beauty[..., 3], lit.beauty[..., 3])  # the same coverage
    assert np.all(r.rgb <= lit.rgb + 1e-6)  # shadows only take light away
    if shadows != "none":
        assert np.sum(r.rgb < lit.rgb - 1e-3) > 20  # and they do
    with pytest.raises(ValueError, match="raster_shadows needs integrator 'raster'"):
        default_scene.render(width=8, height=8, raster_shadows="map")


def test_seed_changes_the_path_traced_image(default_scene):
    a = default_scene.render(width=24, height=14, spp=2, integrator="path", seed=1)
    b = default_scene.render(width=24, height=14, spp=2, integrator="path", seed=2)
    assert not np.array_equal(a.beauty, b.beauty)


def test_camera_by_name_equals_camera_by_index(default_scene):
    by_name = default_scene.render(width=20, height=12, spp=1, camera="room camera")
    by_index = default_scene.render(penumbra.RenderSettings(width=20, height=12, spp=1, camera=0))
    np.testing.assert_array_equal(by_name.beauty, by_index.beauty)
    with pytest.raises(penumbra.InputError) as e:
        default_scene.render(width=20, height=12, camera="nope")
    assert str(e.value) == f"{default_scene.file}: camera: no camera named 'nope' (cameras: 0 'room camera')"
    assert e.value.element == "camera"
    with pytest.raises(penumbra.InputError, match="camera 3 does not exist"):
        default_scene.render(width=20, height=12, camera=3)


def test_no_camera_frames_the_bounds_and_no_light_adds_the_key_light(tmp_path):
    p, i = quad(-1, 1, -1, 1, 0)
    scene = penumbra.load(write_gltf(tmp_path / "bare.gltf", [{"mesh": 0}], [(p, i, None)]))
    r = scene.render(width=32, height=32, spp=1, aovs=["id"])
    assert r.camera_index == -1 and r.default_light
    assert r.aovs["object_id"][16, 16] == 1  # the framed quad fills the centre
    assert scene.lights == []  # the default light lives only for the render


def test_settings_are_checked_before_rendering(default_scene):
    with pytest.raises(ValueError, match="integrator: unknown value 'foo' \\(known: whitted, path, raster\\)"):
        default_scene.render(integrator="foo")
    with pytest.raises(ValueError, match="accel: unknown value 'quadtree'"):
        default_scene.render(accel="quadtree")
    with pytest.raises(ValueError, match="'samples' needs integrator 'path'"):
        default_scene.render(aovs=["samples"])
    with pytest.raises(ValueError, match="unknown AOV 'depth'"):
        default_scene.render(aovs=["depth"])
    with pytest.raises(ValueError, match="env_color needs integrator 'path'"):
        default_scene.render(env_color=1.0)
    with pytest.raises(ValueError, match="background applies to integrator 'whitted'"):
        default_scene.render(integrator="path", background=(0.1, 0.2, 0.3))
    with pytest.raises(ValueError, match="filter: unknown value 'lanczos'"):
        default_scene.render(filter="lanczos")
    with pytest.raises(ValueError, match="accel_params bvh.max_leaf_size=4: a parameter of 'bvh'"):
        default_scene.render(accel_params=["bvh.max_leaf_size=4"])
    with pytest.raises(ValueError):
        default_scene.render(width=20000)
    with pytest.raises(TypeError, match="unknown render setting 'widht'"):
        default_scene.render(widht=10)
    s = penumbra.RenderSettings(width=10, integrator="path")
    assert s.width == 10 and s.copy(width=20).width == 20 and s.width == 10
    assert s.spp == 0 and s.camera is None and s.background is None


def test_accelerator_parameters_keep_the_image(default_scene):
    a = default_scene.render(width=24, height=14, spp=1, accel="bvh", aovs=["Z"])
    b = default_scene.render(width=24, height=14, spp=1, accel="bvh", accel_params=["bvh.max_leaf_size=2"],
                             aovs=["Z"])
    np.testing.assert_array_equal(a.aovs["Z"], b.aovs["Z"])


def test_concurrent_renders_of_one_scene_equal_sequential_ones(default_scene):
    settings = [dict(width=40, height=22, spp=2), dict(width=40, height=22, spp=2, integrator="path")]
    expected = [default_scene.render(**s).beauty for s in settings]
    results = [None, None]

    def run(k):
        results[k] = default_scene.render(**settings[k]).beauty

    threads = [threading.Thread(target=run, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for got, want in zip(results, expected):
        np.testing.assert_array_equal(got, want)


def test_render_releases_the_gil(default_scene):
    """A thread that increments a counter keeps running while another thread renders. With a
    switch interval longer than the render, a render holding the GIL would leave the counter
    exactly where it was when the render began."""
    counter = 0
    stop = threading.Event()
    seen = {}

    def spin():
        nonlocal counter
        while not stop.is_set():
            counter += 1
            time.sleep(0.0005)  # without the GIL, so the render thread gets it back at once

    def render():
        before = counter
        seen["result"] = default_scene.render(width=160, height=90, spp=16)
        seen["during"] = counter - before

    old = sys.getswitchinterval()
    sys.setswitchinterval(30)
    try:
        spinner = threading.Thread(target=spin)
        spinner.start()
        worker = threading.Thread(target=render)
        worker.start()
        worker.join()
        stop.set()
        spinner.join()
    finally:
        sys.setswitchinterval(old)
    assert seen["result"].beauty.shape == (90, 160, 4)
    assert seen["during"] > 0


def test_every_setting_is_a_render_flag_and_the_same_default(cli):
    # The settings spec is one table: each of its fields is a keyword here and a flag of
    # `penumbra render` (dashes for underscores); the rest have flags of their own form.
    import re
    import subprocess

    help_text = subprocess.run([str(cli), "render", "--help"], capture_output=True, text=True, check=True).stdout
    flags = set(re.findall(r"--[a-z][a-z0-9-]*", help_text))
    own_form = {"window": "--crop", "accel_params": "--accel-param", "env_color": "--env", "env_map": "--env"}
    names = re.findall(r"(\w+)=", repr(penumbra.RenderSettings()))
    assert len(names) > 20
    for name in names:
        flag = own_form.get(name, "--" + name.replace("_", "-"))
        assert flag in flags, f"RenderSettings.{name} has no render flag {flag}"
    # An unknown keyword names the known ones, which are exactly these.
    with pytest.raises(TypeError) as e:
        penumbra.RenderSettings(no_such_setting=1)
    for name in names:
        assert name in str(e.value)


def mixed_columns(r):
    """Columns of the middle row whose colour lies strictly between the two quads' (an edge)."""
    red = r.rgb[H // 2, :, 0]
    lo, hi = sorted((red[0], red[-1]))
    return int(np.sum((red > lo + 0.02 * (hi - lo)) & (red < hi - 0.02 * (hi - lo))))


def test_depth_of_field_focuses_where_asked(quads):
    # The front quad's edge lies at depth 2: focused there (autofocus on a pixel of the front quad)
    # it is as sharp as through a pinhole; focused on the back quad (depth 3) it spreads.
    front, back = column_sides()
    base = dict(width=W, height=H, spp=64, integrator="whitted")
    pinhole = quads.render(**base)
    near = quads.render(**base, aperture_radius=0.6, focus_at=f"{front[0]},{H // 2}", aovs=["Z"])
    far = quads.render(**base, aperture_radius=0.6, focus_at=f"{back[-1]},{H // 2}")
    assert mixed_columns(near) <= mixed_columns(pinhole) + 1
    assert mixed_columns(far) >= mixed_columns(pinhole) + 3
    np.testing.assert_allclose(near.aovs["Z"][H // 2, front[0]], 2, rtol=1e-4)
    with pytest.warns(RuntimeWarning, match="ignores depth of field"):
        quads.render(width=W, height=H, integrator="raster", fstop=2)
    with pytest.raises(ValueError, match="fstop and aperture_radius exclude each other"):
        quads.render(fstop=2, aperture_radius=0.1)
    with pytest.raises(ValueError, match="focus_at needs depth of field"):
        quads.render(focus_at="1,1")


def write_animated_quad(path, x0, data, add):
    """A 0.2-wide quad centred at (x0, 0) seen by an orthographic camera 4 units high, written to
    `path` with `data` appended to its buffer; add(gltf, base, views, accessors) adds what uses
    the data (buffer offset `base`, first new buffer view and accessor index)."""
    p, i = quad(x0 - 0.1, x0 + 0.1, -0.1, 0.1, 0)
    path = write_gltf(path, nodes=[{"camera": 0, "translation": [0, 0, 5]}, {"name": "quad", "mesh": 0}],
                      meshes=[(p, i, None)],
                      cameras=[{"type": "orthographic",
                                "orthographic": {"xmag": 2, "ymag": 2, "znear": 0.01, "zfar": 100}}])
    gltf = json.loads(pathlib.Path(path).read_text())
    blob = base64.b64decode(gltf["buffers"][0]["uri"].split(",", 1)[1])
    add(gltf, len(blob), len(gltf["bufferViews"]), len(gltf["accessors"]))
    blob += data
    gltf["buffers"] = [{"byteLength": len(blob),
                        "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}]
    pathlib.Path(path).write_text(json.dumps(gltf))
    return path


def write_sliding_quad(path, speed):
    """The quad of write_animated_quad whose node moves along +X at `speed` units per second,
    through x = 0 at t = 1 (keys at 0 and 2 s)."""
    def add(gltf, base, v, n):
        gltf["bufferViews"] += [{"buffer": 0, "byteOffset": base, "byteLength": 8},
                                {"buffer": 0, "byteOffset": base + 8, "byteLength": 24}]
        gltf["accessors"] += [{"bufferView": v, "componentType": 5126, "count": 2, "type": "SCALAR",
                               "min": [0], "max": [2]},
                              {"bufferView": v + 1, "componentType": 5126, "count": 2, "type": "VEC3"}]
        gltf["animations"] = [{"samplers": [{"input": n, "output": n + 1}],
                               "channels": [{"sampler": 0, "target": {"node": 1, "path": "translation"}}]}]

    keys = np.array([0, 2], np.float32).tobytes() + np.array([-speed, 0, 0, speed, 0, 0], np.float32).tobytes()
    return write_animated_quad(path, 0, keys, add)


def check_streak(scene, **kw):
    """At t = 1 with a one-frame shutter at 24 fps a quad moving 12 units per second sweeps 0.5
    units: its blur spans 0.7 units (11.2 px of 64 over 4 units) and coverage in the middle is
    0.2 / 0.5; the still frame covers about 3 px."""
    r = scene.render(width=64, height=64, spp=256, motion_blur=True, shutter=1, fps=24, **kw)
    row = r.beauty[32, :, 3]
    covered = np.nonzero(row > 0.01)[0]
    assert abs((covered[-1] + 1 - covered[0]) - 11.2) <= 1.5
    np.testing.assert_allclose(row[30:34], 0.4, atol=0.06)
    still = scene.render(width=64, height=64, spp=16, **kw)
    assert np.count_nonzero(still.beauty[32, :, 3] > 0.01) <= 5


def test_motion_blur_streaks_a_moving_quad(tmp_path):
    # The quad's node moves along +X at 12 units per second.
    scene = penumbra.load(write_sliding_quad(tmp_path / "moving.gltf", 12), time=1.0, keep_animation=True)
    check_streak(scene)
    with pytest.raises(ValueError, match="shutter needs motion_blur"):
        scene.render(shutter=1)


def test_motion_blur_streaks_a_morphing_quad(tmp_path):
    # The same motion from a morph target instead of the node: every vertex +24 units in X at
    # weight 1, the weight 0 to 1 over two seconds, the quad at x = -12 at weight 0 (centred at
    # t = 1). The file is loaded at each motion step's time; the streak is as long as the node's.
    def add(gltf, base, v, n):
        gltf["bufferViews"] += [{"buffer": 0, "byteOffset": base, "byteLength": 48},
                                {"buffer": 0, "byteOffset": base + 48, "byteLength": 8},
                                {"buffer": 0, "byteOffset": base + 56, "byteLength": 8}]
        gltf["accessors"] += [{"bufferView": v, "componentType": 5126, "count": 4, "type": "VEC3",
                               "min": [24, 0, 0], "max": [24, 0, 0]},
                              {"bufferView": v + 1, "componentType": 5126, "count": 2, "type": "SCALAR",
                               "min": [0], "max": [2]},
                              {"bufferView": v + 2, "componentType": 5126, "count": 2, "type": "SCALAR"}]
        gltf["meshes"][0]["primitives"][0]["targets"] = [{"POSITION": n}]
        gltf["meshes"][0]["weights"] = [0]
        gltf["animations"] = [{"samplers": [{"input": n + 1, "output": n + 2}],
                               "channels": [{"sampler": 0, "target": {"node": 1, "path": "weights"}}]}]

    data = (np.tile(np.array([24, 0, 0], np.float32), 4).tobytes() + np.array([0, 2], np.float32).tobytes()
            + np.array([0, 1], np.float32).tobytes())
    scene = penumbra.load(write_animated_quad(tmp_path / "morphing.gltf", -12, data, add), time=1.0)
    check_streak(scene, accel="bvh")


def test_velocity_layer_is_the_camera_space_velocity(tmp_path):
    # The quad's node moves +X at 1.5 units per second under a still camera looking down -Z.
    scene = penumbra.load(write_sliding_quad(tmp_path / "sliding.gltf", 1.5), time=1.0)
    r = scene.render(width=32, height=32, spp=1, aovs=["velocity"])
    v = r.aovs["velocity"]
    assert v.shape == (32, 32, 3)
    assert "vector" not in r.aovs
    np.testing.assert_allclose(v[16, 16], [1.5, 0, 0], atol=1e-3)
    np.testing.assert_allclose(v[2, 2], [0, 0, 0])
    exr = tmp_path / "velocity.exr"
    r.write_exr(exr)
    if shutil.which("oiiotool"):
        info = subprocess.run(["oiiotool", "--info", "-v", str(exr)], capture_output=True, text=True).stdout
        assert all(f"velocity.{c}" in info for c in "XYZ")


def test_vector_layer_follows_the_scenes_time():
    # The fly-through's camera moves: at a time the layer is (rows, columns, 4) and not all 0;
    # posed to that time it equals a scene loaded there; a render at the static pose is 0 and warns.
    at = penumbra.load(SCENES / "flythrough.gltf", time=1.0)
    r = at.render(width=32, height=18, spp=1, accel="bvh", aovs=["vector"])
    v = r.aovs["vector"]
    assert v.shape == (18, 32, 4)
    assert np.abs(v).max() > 0.1
    assert "vector" not in at.render(width=32, height=18, spp=1, accel="bvh", aovs=["all"]).aovs
    posed = penumbra.load(SCENES / "flythrough.gltf", time=0.0, keep_animation=True)
    assert posed.pose(1.0)
    np.testing.assert_allclose(posed.render(width=32, height=18, spp=1, accel="bvh", aovs=["vector"]).aovs["vector"],
                               v, atol=1e-4)
    slower = at.render(width=32, height=18, spp=1, accel="bvh", aovs=["vector"], fps=48)
    assert np.abs(slower.aovs["vector"]).max() < np.abs(v).max()
    with pytest.warns(RuntimeWarning, match="static pose"):
        still = penumbra.load(SCENES / "flythrough.gltf").render(width=32, height=18, spp=1, aovs=["vector"])
    assert not np.any(still.aovs["vector"])


def lines_and_points(path, width=None):
    """An orthographic camera one unit per pixel on a 40 x 30 image (ymag 15) looking down -Z at a
    horizontal LINES segment at y = 0.25 (node "line") and a POINTS primitive of one point at
    (10, 8) (node "dot"); `width` sets the file's PENUMBRA_points width of both."""
    write_gltf(path,
               nodes=[{"name": "camera", "camera": 0, "translation": [0, 0, 5]},
                      {"name": "line", "mesh": 0}, {"name": "dot", "mesh": 1}],
               meshes=[([[-30, 0.25, 0], [30, 0.25, 0]], [[0, 1]], None), ([[10, 8, 0]], [[0]], None)],
               cameras=[{"type": "orthographic",
                         "orthographic": {"xmag": 20, "ymag": 15, "znear": 0.1, "zfar": 100}}])
    gltf = json.loads(pathlib.Path(path).read_text())
    gltf["meshes"][0]["primitives"][0]["mode"] = 1
    gltf["meshes"][1]["primitives"][0]["mode"] = 0
    if width is not None:
        for m in gltf["meshes"]:
            m["primitives"][0]["extensions"] = {"PENUMBRA_points": {"width": width}}
        gltf["extensionsUsed"] = ["PENUMBRA_points"]
    pathlib.Path(path).write_text(json.dumps(gltf))
    return penumbra.load(path)


@pytest.mark.parametrize("integrator", ["whitted", "path"])
def test_lines_and_points_render_at_their_width(tmp_path, integrator):
    s = lines_and_points(tmp_path / "lp.gltf")
    r = s.render(width=40, height=30, spp=64, integrator=integrator, filter="box", line_width="3px",
                 point_size="8px", aovs=["id"])
    alpha = r.beauty[..., 3]
    # Away from the point, each column's coverage sums to the line's 3 pixels.
    columns = alpha[:, :25].sum(axis=0)
    np.testing.assert_allclose(columns, 3, atol=0.15)
    # The point: a disc of radius 4 pixels, pi 16 in all (beside the line's 15 columns of 3).
    assert alpha[:, 25:].sum() - 3 * 15 == pytest.approx(math.pi * 16, rel=0.03)
    # Unlit white (no NORMAL): the base colour itself where covered.
    assert r.beauty[14, 5, :3] == pytest.approx([1, 1, 1], abs=0.05)
    # The file's width wins over the flags: 0.5 units.
    f = lines_and_points(tmp_path / "lpw.gltf", width=0.5).render(
        width=40, height=30, spp=64, integrator=integrator, filter="box", line_width="3px")
    np.testing.assert_allclose(f.beauty[..., 3][:, :25].sum(axis=0), 0.5, atol=0.1)
    with pytest.raises(ValueError, match="line_width"):
        s.render(width=8, height=6, line_width="-1px")


def test_wireframe_composites_over_the_beauty_and_is_its_own_layer(quads, tmp_path):
    plain = quads.render(width=W, height=H, spp=4)
    wired = quads.render(width=W, height=H, spp=4, wireframe=True, wireframe_color="1,0,0", wireframe_width=2)
    a = wired.aovs["wireframe"][..., None]
    assert a.shape == (H, W, 1) and a.max() > 0.9 and a.min() == 0
    expected = np.array([1, 0, 0], np.float32) * a + plain.beauty[..., :3] * (1 - a)
    np.testing.assert_allclose(wired.beauty[..., :3], expected, atol=1e-5)
    # Only the front node's edges: none where only the back quad is seen.
    front_only = quads.render(width=W, height=H, spp=4, wireframe=True, wireframe_nodes="front")
    front, back = column_sides()
    assert front_only.aovs["wireframe"][:, back[2:]].max() == 0
    assert "wireframe" not in plain.aovs
    if shutil.which("oiiotool"):
        wired.write_exr(tmp_path / "w.exr")
        info = subprocess.run([shutil.which("oiiotool"), "--info", "-v", str(tmp_path / "w.exr")],
                              capture_output=True, text=True, check=True).stdout
        assert "wireframe.A" in info
    with pytest.raises(ValueError, match="wireframe_nodes"):
        quads.render(width=8, height=6, wireframe=True, wireframe_nodes="nosuch")
    with pytest.raises(ValueError, match="needs wireframe"):
        quads.render(width=8, height=6, wireframe_width=3)


def test_a_framed_render_of_points_and_lines_is_the_same_the_second_time(tmp_path):
    # No camera: the view frames the bounds, which the sizes a render gives in pixels must not move.
    write_gltf(tmp_path / "framed.gltf", nodes=[{"name": "line", "mesh": 0}, {"name": "dot", "mesh": 1}],
               meshes=[([[-1, 0, 0], [1, 0.5, 0]], [[0, 1]], None), ([[0, 1, 0.5]], [[0]], None)])
    gltf = json.loads((tmp_path / "framed.gltf").read_text())
    gltf["meshes"][0]["primitives"][0]["mode"] = 1
    gltf["meshes"][1]["primitives"][0]["mode"] = 0
    (tmp_path / "framed.gltf").write_text(json.dumps(gltf))
    s = penumbra.load(tmp_path / "framed.gltf")
    first = s.render(width=48, height=32, spp=4, point_size="12px", line_width="4px")
    second = s.render(width=48, height=32, spp=4, point_size="12px", line_width="4px")
    np.testing.assert_array_equal(first.beauty, second.beauty)
    assert first.beauty[..., 3].sum() > 20


def test_gaussian_splats_ray_traced_and_rasterised_agree(tmp_path):
    # The shipped splat sphere alone, seen by its camera: the library's raster preview and ray
    # tracer within the documented tolerance, the splats carrying their node's object id.
    gltf = read_gltf(SCENES / "splats.gltf")
    keep = [i for i, n in enumerate(gltf["nodes"]) if n["name"] in ("splat sphere", "camera")]
    gltf["scenes"][0]["nodes"] = keep
    (tmp_path / "sphere.gltf").write_text(json.dumps(gltf))
    s = penumbra.load(tmp_path / "sphere.gltf")
    traced = s.render(width=96, height=54, spp=4, aovs=["id"])
    raster = s.render(width=96, height=54, spp=4, integrator="raster", aovs=["id"])
    assert np.abs(traced.beauty - raster.beauty).mean() < 0.003
    ids = traced.aovs["object_id"]
    sphere = keep[0] + 1
    assert (ids == sphere).sum() > 200
    # At the middle of the sphere's pixels the splats face the camera: colour 0.5 + 0.5 n for n
    # from the centre (0, 0.75, 0) towards the eye (0, 1.6, 4.6).
    rows, cols = np.nonzero(ids == sphere)
    y, x = int(round(rows.mean())), int(round(cols.mean()))
    n = np.array([0, 0.85, 4.6]) / np.linalg.norm([0, 0.85, 4.6])
    assert traced.beauty[y, x, :3] == pytest.approx(0.5 + 0.5 * n, abs=0.05)
    assert traced.beauty[y, x, 3] > 0.99  # overlapping splats of opacity 0.95
