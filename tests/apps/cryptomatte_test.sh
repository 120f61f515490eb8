#!/usr/bin/env bash
# Cryptomatte metadata from the command line, checked with an independent MurmurHash3 in Python:
# every manifest entry is the hash of its name converted as the specification says; the key is
# the layer name's hash; --crypto-depth sets the channel groups; a manifest too large for the
# header goes into a sidecar JSON named by manif_file; bad values are errors.
# Usage: cryptomatte_test.sh PENUMBRA SRC WORK_DIR
set -u
penumbra="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"
fails=0; passes=0
source "$src/tests/apps/expect.sh"
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
py=/usr/bin/python3

# check_manifests EXR: every cryptomatte/<key>/ block is complete and its manifest (inline or
# sidecar) maps each name to the specification's hash of it.
check_manifests() {
  oiiotool --info -v "$1" >"$work/header.txt"
  "$py" - "$1" "$work/header.txt" <<'PY' || fail "manifests of $1"
import json, os, re, struct, sys

def murmur3(data, seed=0):
    c1, c2, h, n = 0xCC9E2D51, 0x1B873593, seed, len(data)
    for i in range(0, n - n % 4, 4):
        k = int.from_bytes(data[i:i + 4], "little")
        k = (k * c1) & 0xFFFFFFFF; k = ((k << 15) | (k >> 17)) & 0xFFFFFFFF; k = (k * c2) & 0xFFFFFFFF
        h ^= k; h = ((h << 13) | (h >> 19)) & 0xFFFFFFFF; h = (h * 5 + 0xE6546B64) & 0xFFFFFFFF
    tail, k = data[n - n % 4:], 0
    for i in reversed(range(len(tail))):
        k = (k << 8) | tail[i]
    if tail:
        k = (k * c1) & 0xFFFFFFFF; k = ((k << 15) | (k >> 17)) & 0xFFFFFFFF; k = (k * c2) & 0xFFFFFFFF; h ^= k
    h ^= n; h ^= h >> 16; h = (h * 0x85EBCA6B) & 0xFFFFFFFF; h ^= h >> 13; h = (h * 0xC2B2AE35) & 0xFFFFFFFF
    return h ^ (h >> 16)

def spec_hex(name):
    h = murmur3(name.encode())
    exp = min(max((h >> 23) & 0xFF, 1), 254)
    return "%08x" % ((h & 0x807FFFFF) | exp << 23)

exr, header = sys.argv[1], open(sys.argv[2]).read()
attrs = dict(re.findall(r'^\s*(cryptomatte/[0-9a-f]{7}/\w+): "(.*)"$', header, re.M))
keys = sorted({k.split("/")[1] for k in attrs})
assert keys, "no cryptomatte attributes"
for key in keys:
    name = attrs["cryptomatte/%s/name" % key]
    assert key == ("%08x" % murmur3(name.encode()))[:7], key
    assert attrs["cryptomatte/%s/hash" % key] == "MurmurHash3_32"
    assert attrs["cryptomatte/%s/conversion" % key] == "uint32_to_float32"
    if "cryptomatte/%s/manif_file" % key in attrs:
        side = os.path.join(os.path.dirname(exr), attrs["cryptomatte/%s/manif_file" % key])
        manifest = json.load(open(side))
        print("sidecar", os.path.basename(side), len(manifest))
    else:
        manifest = json.loads(attrs["cryptomatte/%s/manifest" % key].replace('\\"', '"'))
        print("inline", name, len(manifest))
    for entry, value in manifest.items():
        assert value == spec_hex(entry), (entry, value, spec_hex(entry))
PY
}

d="$src/scenes/default.gltf"
expect 0 "c.exr" -- "$penumbra" render "$d" -o "$work/c.exr" --width 48 --spp 2 --aov crypto_object,crypto_material,crypto_asset -q
check_manifests "$work/c.exr"
expect 0 "CryptoObject02.A" -- oiiotool --info -v "$work/c.exr"
expect 0 "d3.exr" -- "$penumbra" render "$d" -o "$work/d3.exr" --width 48 --spp 2 --aov crypto_object --crypto-depth 3 -q
expect 0 "CryptoObject01.A \(float\)$" -- oiiotool --info -v "$work/d3.exr"
oiiotool --info -v "$work/d3.exr" | grep -q "CryptoObject02" && fail "--crypto-depth 3 wrote a third channel group"
expect 2 "--crypto-depth needs --aov crypto_object" -- "$penumbra" render "$d" -o "$work/x.exr" --crypto-depth 4
expect 2 "crypto-depth" -- "$penumbra" render "$d" -o "$work/x.exr" --aov crypto_object --crypto-depth 0
expect 2 "--compression dwaa is lossy for float channels" -- "$penumbra" render "$d" -o "$work/x.exr" --aov all --compression dwaa
expect 0 "mpd.exr" -- "$penumbra" render "$d" -o "$work/mpd.exr" --width 32 --spp 1 --aov crypto_object --compression dwaa --multipart -q
[ ! -e "$work/x.exr" ] || fail "a refused render left x.exr"

# 3000 objects with long names: the object manifest exceeds the header's limit.
"$py" - "$work/many.gltf" <<'PY'
import base64, json, struct, sys
pos = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
buf = base64.b64encode(pos).decode()
nodes = [{"name": "object number %04d with a long descriptive name" % i, "mesh": 0,
          "translation": [(i % 60) * 1.2 - 36, (i // 60) * 1.2 - 30, -40]} for i in range(3000)]
gltf = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": list(range(3000))}], "nodes": nodes,
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [0, 0, 0], "max": [1, 1, 0]}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64," + buf}]}
json.dump(gltf, open(sys.argv[1], "w"))
PY
expect 0 "many.exr" -- "$penumbra" render "$work/many.gltf" -o "$work/many.exr" --width 64 --spp 1 --aov crypto_object,crypto_material -q
expect 0 'cryptomatte/[0-9a-f]{7}/manif_file: "many.CryptoObject.json"' -- oiiotool --info -v "$work/many.exr"
expect 0 "sidecar many.CryptoObject.json 3000" -- check_manifests "$work/many.exr"
expect 0 "inline CryptoMaterial 1" -- check_manifests "$work/many.exr"
# Farm stripes: the merged frame's manifest sidecar is beside it, under its name.
for i in 0 1; do
  expect 0 "many$i.exr" -- "$penumbra" render "$work/many.gltf" -o "$work/many$i.exr" --width 64 --spp 1 \
    --aov crypto_object --tile $i/2 -q --no-png
done
mkdir -p "$work/merged"
expect 0 "" -- "$penumbra" merge "$work/many0.exr" "$work/many1.exr" -o "$work/merged/frame.exr"
expect 0 'manif_file: "frame.CryptoObject.json"' -- oiiotool --info -v "$work/merged/frame.exr"
expect 0 "sidecar frame.CryptoObject.json 3000" -- check_manifests "$work/merged/frame.exr"
rm "$work/many0.CryptoObject.json"
expect 2 "many0.CryptoObject.json" -- "$penumbra" merge "$work/many0.exr" "$work/many1.exr" -o "$work/merged/gone.exr"
[ ! -e "$work/merged/gone.exr" ] || fail "a merge without its manifest wrote gone.exr"

echo "cryptomatte: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
