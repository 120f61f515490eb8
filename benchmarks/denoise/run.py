#!/usr/bin/env python3
"""The denoiser's benchmark: error, bias and cost of NFOR and of the cross-bilateral baseline on
corpus scenes, against each scene's own converged reference, through the Python module (the same
library as `penumbra render --denoise`).

For each scene (the Cycles benchmark's cameras, benchmarks/cycles/add_camera.py): a REF_SPP
reference (another seed), then for each low spp N in SPPS a render with the halves, denoised by
NFOR and by the cross-bilateral filter, and an undenoised render at 16 N spp. Reports relMSE
(mean over pixels and RGB of (x - ref)^2 / (ref^2 + 0.01)), the ratio relMSE(N denoised) /
relMSE(16 N noisy) (target <= 1), the mean luminance bias of the denoised frame against the
reference, and render and denoise seconds. With --timing WxH, also the render time of 16 spp and
the denoise time of one frame at that size (target: denoise <= render), median of 3. Writes crops
(reference / noisy / denoised) as PNG for the docs with --crops DIR.

usage: PYTHONPATH=build/python /usr/bin/python3 benchmarks/denoise/run.py [--scenes a,b]
       [--size 320x180] [--ref-spp 4096] [--spps 16,64] [--threads 2] [--timing 1920x1080]
       [--crops DIR] [--out FILE]
"""
import argparse
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import penumbra

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
CORPUS = pathlib.Path(os.environ.get("PENUMBRA_CORPUS", ROOT.parent / "shared" / "corpus"))
V = CORPUS / "valid"
# name, what it stands for, file, eye, yfov, pitch, constant environment radiance
SCENES = {
    "cornell": ("the Cornell box (area light, diffuse)", V / "CornellBox-Vinc3r/glTF/cornellBox-2.80-Eevee-gltf.gltf",
                (0, 1.5, 5.6), 0.75, 0, 0),
    "helmet": ("environment-lit, textured", V / "DamagedHelmet/glTF-Binary/DamagedHelmet.glb", (0, 0, 2.7), 0.75, 0, 1),
    "bottle": ("glossy, textured", V / "WaterBottle/glTF/WaterBottle.gltf", (0, 0, 0.37), 0.75, 0, 1),
    "transmission": ("transmission", V / "TransmissionTest/glTF-Binary/TransmissionTest.glb", (0, 0.75, 1.5), 0.75,
                     -22, 1),
    "shoe": ("fine geometry (laces, stitching), textured",
             CORPUS / "extensions/MaterialsVariantsShoe/glTF/MaterialsVariantsShoe.gltf", (0, 0.12, 0.32), 0.75, -8, 1),
    "avocado": ("textured, rough", V / "Avocado/glTF/Avocado.gltf", (0, 0.031, 0.1), 0.75, 0, 1),
}


def rel_mse(x, ref):
    x, ref = x[..., :3].astype(np.float64), ref[..., :3].astype(np.float64)
    return float(np.mean((x - ref) ** 2 / (ref ** 2 + 0.01)))


def luminance(img):
    return float(np.mean(0.2126 * img[..., 0] + 0.7152 * img[..., 1] + 0.0722 * img[..., 2]))


def halves(a):
    return dict(color=np.stack([a["even"], a["odd"]]), albedo=np.stack([a["even_albedo"], a["odd_albedo"]]),
                normal=np.stack([a["even_N"], a["odd_N"]]), depth=np.stack([a["even_Z"], a["odd_Z"]]))


def with_camera(name, work):
    _, file, eye, yfov, pitch, _ = SCENES[name]
    out = subprocess.run([sys.executable, str(HERE.parent / "cycles" / "add_camera.py"), str(file), str(work / name),
                          *map(str, eye), str(yfov), str(pitch)], check=True, capture_output=True, text=True)
    return out.stdout.strip()


def write_png(img, path):
    """Writes a premultiplied scene-linear RGBA float image as an sRGB-encoded 8-bit PNG
    (enlarged 2x, nearest), through a PPM and oiiotool."""
    c = np.clip(img[..., :3], 0, 1)
    c = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1 / 2.4) - 0.055)
    c = np.repeat(np.repeat(c, 2, axis=0), 2, axis=1)
    h, w = c.shape[:2]
    ppm = path.with_suffix(".ppm")
    ppm.write_bytes(f"P6 {w} {h} 255\n".encode() + (c * 255 + 0.5).astype(np.uint8).tobytes())
    subprocess.run(["oiiotool", str(ppm), "-o", str(path)], check=True, capture_output=True)
    ppm.unlink()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--size", default="320x180")
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--spps", default="16,64")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--timing", default="")
    ap.add_argument("--out", default="")
    ap.add_argument("--crops", default="", help="folder for reference / noisy / denoised PNGs of the first spp")
    args = ap.parse_args()
    width, height = (int(v) for v in args.size.split("x"))
    spps = [int(v) for v in args.spps.split(",")]
    work = pathlib.Path(tempfile.mkdtemp(prefix="penumbra-denoise-"))
    lines = [f"# penumbra denoiser benchmark, {time.strftime('%Y-%m-%dT%H:%MZ', time.gmtime())}",
             f"# command: benchmarks/denoise/run.py --size {args.size} --ref-spp {args.ref_spp} --spps {args.spps} "
             f"--threads {args.threads}" + (f" --timing {args.timing}" if args.timing else ""),
             "# relMSE = mean (x - ref)^2 / (ref^2 + 0.01) over pixels and RGB; ratio = relMSE(N denoised) / "
             "relMSE(16N noisy); bias = mean luminance of the denoised frame / the reference's - 1",
             "# columns: scene spp relmse_noisy relmse_nfor relmse_crossbilateral relmse_noisy_16x ratio bias_nfor "
             "render_s denoise_s"]

    def emit(line):
        print(line, flush=True)
        lines.append(line)

    for line in lines:
        print(line)
    for name in args.scenes.split(","):
        what, _, _, _, _, env = SCENES[name]
        scene = penumbra.load(with_camera(name, work))
        common = dict(integrator="path", width=width, height=height, camera="bench", threads=args.threads,
                      env_color=(env, env, env))
        ref = scene.render(spp=args.ref_spp, seed=1, **common).beauty.copy()
        emit(f"# {name}: {what}; reference {args.ref_spp} spp, mean luminance {luminance(ref):.4f}")
        for n in spps:
            t0 = time.perf_counter()
            r = scene.render(spp=n, aovs=["halves"], **common)
            render_s = time.perf_counter() - t0
            h = halves(r.aovs)
            t0 = time.perf_counter()
            nfor = penumbra.denoise(**h, threads=args.threads)
            denoise_s = time.perf_counter() - t0
            cb = penumbra.denoise(**h, threads=args.threads, method="cross_bilateral")
            noisy16 = scene.render(spp=16 * n, **common).beauty
            e_noisy, e_nfor, e_cb = rel_mse(r.beauty, ref), rel_mse(nfor, ref), rel_mse(cb, ref)
            e16 = rel_mse(noisy16, ref)
            bias = luminance(nfor) / luminance(ref) - 1
            emit(f"{name} {n} {e_noisy:.5g} {e_nfor:.5g} {e_cb:.5g} {e16:.5g} {e_nfor / e16:.3f} {bias:+.4f} "
                 f"{render_s:.2f} {denoise_s:.2f}")
            if args.crops and n == spps[0]:
                crops = pathlib.Path(args.crops)
                crops.mkdir(parents=True, exist_ok=True)
                for kind, img in (("reference", ref), ("noisy", r.beauty), ("denoised", nfor)):
                    write_png(img, crops / f"{name}-{kind}.png")
    if args.timing:
        tw, th = (int(v) for v in args.timing.split("x"))
        name = args.scenes.split(",")[0]
        scene = penumbra.load(with_camera(name, work))
        env = SCENES[name][5]
        common = dict(integrator="path", width=tw, height=th, camera="bench", threads=args.threads,
                      env_color=(env, env, env))
        render_times, denoise_times = [], []
        for _ in range(3):
            t0 = time.perf_counter()
            r = scene.render(spp=16, aovs=["halves"], **common)
            render_times.append(r.stats["seconds"])
            h = halves(r.aovs)
            t0 = time.perf_counter()
            penumbra.denoise(**h, threads=args.threads)
            denoise_times.append(time.perf_counter() - t0)
        emit(f"# timing {name} {args.timing}, {args.threads} threads, median of 3: render 16 spp "
             f"{statistics.median(render_times):.2f} s, denoise {statistics.median(denoise_times):.2f} s")
    if args.out:
        pathlib.Path(args.out).write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
