# Bad input through penumbra.load raises penumbra.InputError (a ValueError) whose text is exactly
# what `penumbra info` prints after "penumbra: error: " for the same file, with the file and the
# element as attributes; the loader's warnings arrive as penumbra.SceneWarning.
import json
import subprocess

import pytest

import penumbra
from conftest import quad, write_gltf

PREFIX = "penumbra: error: "


def bad_accessor(tmp_path):
    p, i = quad(-1, 1, -1, 1, 0)
    path = write_gltf(tmp_path / "accessor.gltf", [{"mesh": 0}], [(p, i, None)])
    gltf = json.loads(path.read_text())
    gltf["accessors"][0]["count"] = 1000  # reads past the end of its buffer view
    path.write_text(json.dumps(gltf))
    return path.name


def bad_node(tmp_path):
    p, i = quad(-1, 1, -1, 1, 0)
    path = write_gltf(tmp_path / "node.gltf", [{"mesh": 7}], [(p, i, None)])
    return path.name


CASES = {
    "missing": lambda d: "missing.gltf",
    "not json": lambda d: (d / "broken.gltf").write_text("{ this is not json") and "broken.gltf",
    "empty": lambda d: (d / "empty.gltf").write_text("") or "empty.gltf",
    "directory": lambda d: (d / "folder.gltf").mkdir() or "folder.gltf",
    "another format": lambda d: (d / "model.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n") and "model.obj",
    "accessor out of range": bad_accessor,
    "mesh index out of range": bad_node,
}


@pytest.mark.parametrize("case", list(CASES))
def test_input_error_carries_the_commands_message(tmp_path, monkeypatch, cli, case):
    name = CASES[case](tmp_path)
    run = subprocess.run([cli, "info", name], cwd=tmp_path, capture_output=True, text=True)
    assert run.returncode == 2
    line = run.stderr.strip().splitlines()[-1]
    assert line.startswith(PREFIX)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(penumbra.InputError) as e:
        penumbra.load(name)
    assert str(e.value) == line[len(PREFIX):]
    assert isinstance(e.value, ValueError)
    assert e.value.file == name
    assert str(e.value).startswith(name)


def test_element_names_the_json_path(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(penumbra.InputError) as e:
        penumbra.load(bad_node(tmp_path))
    assert e.value.element.startswith("nodes[0]")
    assert str(e.value).startswith(f"node.gltf: {e.value.element}: ")


def test_warnings_are_scene_warnings(tmp_path):
    p, i = quad(-1, 1, -1, 1, 0)
    path = write_gltf(tmp_path / "points.gltf", [{"mesh": 0}, {"mesh": 1}], [(p, i, None), (p, i, None)])
    gltf = json.loads(path.read_text())
    del gltf["meshes"][1]["primitives"][0]["attributes"]["POSITION"]  # skipped, with a warning
    path.write_text(json.dumps(gltf))
    with pytest.warns(penumbra.SceneWarning, match="points.gltf: .*meshes\\[1\\]"):
        scene = penumbra.load(path)
    assert len(scene.warnings) == 1 and len(scene.instances) == 1 and "POSITION" in scene.warnings[0]
    assert issubclass(penumbra.SceneWarning, UserWarning)
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        penumbra.load(path, quiet=True)


def test_settings_of_the_wrong_type_or_out_of_range_name_the_setting(default_scene, tmp_path):
    with pytest.raises(ValueError, match=r"camera index 1180591620717411303424 is out of range \[0, 2147483647\]"):
        penumbra.RenderSettings(camera=2**70)
    with pytest.raises(ValueError, match=r"camera index -1 is out of range"):
        default_scene.render(camera=-1)
    with pytest.raises(TypeError, match=r"camera must be None, an index \(int\) or a name \(str\), not float"):
        penumbra.RenderSettings(camera=0.5)
    with pytest.raises(ValueError, match="camera name must not be empty"):
        penumbra.RenderSettings(camera="")
    with pytest.raises(ValueError, match=r"window value 1180591620717411303424 is out of range"):
        penumbra.RenderSettings(window=(0, 2**70, 0, 10))
    with pytest.raises(TypeError, match=r"window must be None or \(x0, y0, x1, y1\), not int"):
        penumbra.RenderSettings(window=5)
    with pytest.raises(TypeError, match=r"window must be None or \(x0, y0, x1, y1\) of ints, not float"):
        penumbra.RenderSettings(window=(0, 0, 1.5, 1))
    with pytest.raises(ValueError, match=r"window must be None or \(x0, y0, x1, y1\) \(4 values\)"):
        penumbra.RenderSettings(window=(0, 0, 1))
    with pytest.raises(TypeError, match="settings must be a penumbra.RenderSettings or None, not int"):
        default_scene.render(settings=5)
    with pytest.raises(TypeError, match="settings must be a penumbra.RenderSettings or None, not str"):
        default_scene.render_to_file(tmp_path / "x.exr", settings="fast")
    assert not (tmp_path / "x.exr").exists()
    # In range, the values are kept.
    s = penumbra.RenderSettings(camera=2147483647, window=[1, 2, 3, 4])
    assert s.camera == 2147483647 and s.window == (1, 2, 3, 4)
