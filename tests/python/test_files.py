# Scene.render_to_file and RenderResult.write_exr / write_display through real files read back
# by OpenImageIO's oiiotool: the EXR holds the in-memory beauty and AOVs (exactly as float,
# rounded to half as half), the display image has the frame's size, and the EXR of a render
# equals, channel for channel and pixel for pixel, the one `penumbra render` writes.
import subprocess

import numpy as np
import pytest

import penumbra
from conftest import SCENES


def oiio_info(path):
    return subprocess.run(["oiiotool", "--info", "-v", str(path)], check=True, capture_output=True,
                          text=True).stdout


def channels(path):
    """The file's channel names in file order (OpenEXR sorts them by name after R, G, B, A)."""
    line = next(l for l in oiio_info(path).splitlines() if "channel list:" in l)
    return [c.split("(")[0].strip() for c in line.split(":", 1)[1].split(",")]


def dump_lines(path):
    out = subprocess.run(["oiiotool", "--dumpdata", str(path)], check=True, capture_output=True, text=True).stdout
    return [l.strip() for l in out.splitlines() if l.strip().startswith("Pixel (")]


def pixels(path, width, height):
    """The file's pixels as float64 (height, width, channels), parsed from oiiotool --dumpdata."""
    rows = {}
    for line in dump_lines(path):
        where, values = line[len("Pixel ("):].split("):")
        x, y = (int(v) for v in where.split(","))
        rows[(y, x)] = [float(v) for v in values.split()]
    assert len(rows) == width * height
    return np.array([[rows[(y, x)] for x in range(width)] for y in range(height)])


def test_exr_holds_the_in_memory_render(tmp_path, default_scene):
    exr, png = tmp_path / "py.exr", tmp_path / "py.png"
    r = default_scene.render_to_file(exr, png=png, width=24, height=14, spp=2, aovs=["Z", "id", "albedo"],
                                     half=False)
    names = channels(exr)
    assert sorted(names) == sorted(["R", "G", "B", "A", "albedo.R", "albedo.G", "albedo.B", "Z", "object_id.X",
                                    "material_id.X"])
    info = oiio_info(exr)
    assert "float openexr" in info and "half" not in info.split("channel list:")[1].splitlines()[0]
    assert 'penumbra:camera: "room camera"' in info
    assert "penumbra:manifest" in info
    px = pixels(exr, 24, 14)
    c = {name: px[..., k] for k, name in enumerate(names)}
    # oiiotool prints 9 decimals: equal within that rounding.
    close = dict(rtol=1e-7, atol=1e-9)
    np.testing.assert_allclose(np.stack([c[k] for k in "RGBA"], axis=-1), r.beauty, **close)
    np.testing.assert_allclose(np.stack([c["albedo." + k] for k in "RGB"], axis=-1), r.aovs["albedo"], **close)
    np.testing.assert_allclose(c["Z"], r.aovs["Z"], **close)
    np.testing.assert_array_equal(c["object_id.X"], r.aovs["object_id"])
    np.testing.assert_array_equal(c["material_id.X"], r.aovs["material_id"])
    assert "24 x   14, 3 channel, uint8 png" in oiio_info(png)


def test_half_exr_is_the_beauty_rounded_to_half(tmp_path, default_scene):
    r = default_scene.render(width=16, height=9, spp=1, aovs=["Z"])
    r.write_exr(tmp_path / "half.exr", metadata={"shot": "010"})
    assert "5 channel, half/half/half/half/float openexr" in oiio_info(tmp_path / "half.exr")
    assert channels(tmp_path / "half.exr") == ["R", "G", "B", "A", "Z"]
    assert 'shot: "010"' in oiio_info(tmp_path / "half.exr")
    px = pixels(tmp_path / "half.exr", 16, 9)
    np.testing.assert_allclose(px[..., :4], r.beauty.astype(np.float16).astype(np.float64), rtol=1e-7,
                               atol=1e-9)
    np.testing.assert_allclose(px[..., 4], r.aovs["Z"], rtol=1e-7, atol=1e-9)  # data stays float


def test_display_image_of_the_half_beauty_equals_one_from_the_file(tmp_path, default_scene):
    r = default_scene.render_to_file(tmp_path / "a.exr", png=tmp_path / "a.png", width=20, height=12, spp=1)
    r.write_display(tmp_path / "b.png", half_beauty=True)
    assert dump_lines(tmp_path / "a.png") == dump_lines(tmp_path / "b.png")
    r.write_display(tmp_path / "c.png", exposure=2.0)
    assert dump_lines(tmp_path / "c.png") != dump_lines(tmp_path / "a.png")


def test_bad_outputs_are_refused_before_rendering(tmp_path, default_scene):
    with pytest.raises(ValueError, match="the output must be an .exr file"):
        default_scene.render_to_file(tmp_path / "out.png", width=8, height=8)
    with pytest.raises(penumbra.InputError):
        default_scene.render_to_file(tmp_path / "out.exr", png=tmp_path / "out.png", view="No Such View",
                                     width=8, height=8)
    assert not (tmp_path / "out.exr").exists()
    with pytest.raises(penumbra.InputError, match="no_such_folder' does not exist"):
        default_scene.render(width=8, height=8, spp=1).write_exr(tmp_path / "no_such_folder" / "x.exr")


@pytest.mark.parametrize("integrator,aovs", [("whitted", "Z,id,albedo,N,P,UV"), ("path", "Z,samples,variance")])
def test_exr_equals_the_commands(tmp_path, cli, integrator, aovs):
    cmd = [cli, "render", str(SCENES / "default.gltf"), "-o", str(tmp_path / "cli.exr"), "--no-png", "-q",
           "--float", "--width", "30", "--height", "17", "--spp", "4", "--integrator", integrator, "--aov", aovs]
    subprocess.run(cmd, check=True, capture_output=True)
    scene = penumbra.load(SCENES / "default.gltf")
    scene.render_to_file(tmp_path / "py.exr", width=30, height=17, spp=4, integrator=integrator,
                         aovs=aovs.split(","), half=False)
    assert channels(tmp_path / "py.exr") == channels(tmp_path / "cli.exr")
    assert dump_lines(tmp_path / "py.exr") == dump_lines(tmp_path / "cli.exr")
