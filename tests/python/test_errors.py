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
    gltf["meshes"][1]["primitives"][0]["mode"] = 0  # points: skipped with a warning
    path.write_text(json.dumps(gltf))
    with pytest.warns(penumbra.SceneWarning, match="points.gltf: .*meshes\\[1\\]"):
        scene = penumbra.load(path)
    assert len(scene.warnings) == 1 and len(scene.instances) == 1
    assert issubclass(penumbra.SceneWarning, UserWarning)
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        penumbra.load(path, quiet=True)
