#!/usr/bin/env python3
"""Writes a copy of a glTF (.gltf with its resources, or .glb) with one more camera node, so
that Penumbra and Blender Cycles render exactly the same view.

usage: add_camera.py IN.gltf|IN.glb OUTDIR EYE_X EYE_Y EYE_Z YFOV_RADIANS [PITCH_DEGREES] [--optional-extensions]
The camera sits at EYE looking down -Z (glTF's camera convention) turned by PITCH about +X
(90 looks along +Y with +Z up), with aspect 16:9. --optional-extensions empties
extensionsRequired, so that an importer without one of them loads the rest (Blender 3.4 refuses
files that require KHR_materials_iridescence)."""
import json, math, os, shutil, struct, sys

optional = "--optional-extensions" in sys.argv
if optional:
    sys.argv.remove("--optional-extensions")
src, outdir = sys.argv[1], sys.argv[2]
eye = [float(v) for v in sys.argv[3:6]]
yfov = float(sys.argv[6])
pitch = math.radians(float(sys.argv[7])) if len(sys.argv) > 7 else 0.0
os.makedirs(outdir, exist_ok=True)


def add_camera(doc):
    doc.setdefault("cameras", []).append(
        {"type": "perspective", "name": "bench", "perspective": {"yfov": yfov, "aspectRatio": 16 / 9, "znear": 0.01}})
    doc.setdefault("nodes", []).append({"name": "bench_camera", "camera": len(doc["cameras"]) - 1, "translation": eye,
                                        "rotation": [math.sin(pitch / 2), 0, 0, math.cos(pitch / 2)]})
    scene = doc["scenes"][doc.get("scene", 0)]
    scene.setdefault("nodes", []).append(len(doc["nodes"]) - 1)
    if optional:
        doc.pop("extensionsRequired", None)
    return doc


name = os.path.basename(src)
if src.endswith(".glb"):
    data = open(src, "rb").read()
    magic, version, length = struct.unpack_from("<III", data, 0)
    jlen, jtype = struct.unpack_from("<II", data, 12)
    doc = add_camera(json.loads(data[20:20 + jlen]))
    rest = data[20 + jlen:]
    js = json.dumps(doc).encode()
    js += b" " * ((4 - len(js) % 4) % 4)
    body = struct.pack("<II", len(js), jtype) + js + rest
    open(os.path.join(outdir, name), "wb").write(struct.pack("<III", magic, version, 12 + len(body)) + body)
else:
    doc = add_camera(json.load(open(src)))
    for key in ("buffers", "images"):
        for item in doc.get(key, []):
            uri = item.get("uri", "")
            if uri and not uri.startswith("data:"):
                shutil.copy(os.path.join(os.path.dirname(src), uri), os.path.join(outdir, uri))
    json.dump(doc, open(os.path.join(outdir, name), "w"))
print(os.path.join(outdir, name))
