#!/usr/bin/env python3
"""Summary table of a benchmarks/cycles/run.sh result file (Markdown, on stdout).

usage: summarize.py RESULTS.txt

Per scene, Penumbra against Cycles:
- samples/s at each spp N of the run, in total (pixels x N / seconds) and marginal
  (pixels x (N - 1) / (seconds at N - seconds at 1 spp)): the marginal figure leaves out each
  renderer's fixed cost, which for Cycles includes Blender's scene set-up;
- the RMSE of each renderer at the largest N against its own reference;
- the time each renderer needs to reach the larger of those two RMSEs, interpolated on a
  log-log line through its two renders nearest to that RMSE (extrapolated past the ends), in
  total time and in marginal time (minus its 1-spp time). Ratios are Cycles / Penumbra, so
  above 1 means Penumbra is faster.
Lines starting with '#' or '|' are skipped, so the table can be appended to the file it reads."""
import math
import sys
from collections import defaultdict

rows = defaultdict(dict)  # (scene, renderer) -> spp -> (seconds, rmse)
order = []
pixels = None
for line in open(sys.argv[1]):
    if line.startswith("# pixels:"):
        pixels = int(line.split()[2].rstrip(";"))
    if not line.strip() or line[0] in "#|":
        continue
    f = line.split()
    if len(f) < 6 or f[4] == "reference":
        continue
    scene, renderer, spp, seconds, rmse = f[0], f[1], int(f[2]), float(f[3]), float(f[5])
    rows[(scene, renderer)][spp] = (seconds, rmse)
    if scene not in order:
        order.append(scene)
if pixels is None:
    sys.exit("summarize.py: no '# pixels:' line in " + sys.argv[1])


def time_to(points, target):
    """Seconds to reach RMSE `target` on the log-log line through the two (seconds, rmse)
    points whose RMSEs bracket it (else the two nearest)."""
    pts = sorted(points, key=lambda p: -p[1])  # falling RMSE
    if len(pts) < 2:
        return float("nan")
    i = 0
    while i + 2 < len(pts) and pts[i + 1][1] > target:
        i += 1
    (t0, e0), (t1, e1) = pts[i], pts[i + 1]
    if t0 <= 0 or t1 <= 0 or e0 == e1:
        return float("nan")
    s = (math.log(t1) - math.log(t0)) / (math.log(e1) - math.log(e0))
    return math.exp(math.log(t0) + s * (math.log(target) - math.log(e0)))


def fmt(x, digits=2):
    return "–" if x != x else f"{x:.{digits}f}"


spps = sorted({n for r in rows.values() for n in r if n > 1})
head = ["scene"]
for n in spps:
    head.append(f"marginal samples/s at {n} spp, Penumbra / Cycles (M)")
head += [f"total at {spps[-1]} spp", f"RMSE at {spps[-1]} spp, Penumbra / Cycles",
         "time to the larger RMSE, Penumbra / Cycles", "marginal time to it"]
print("| " + " | ".join(head) + " |")
print("|" + "---|" * len(head))
for scene in order:
    p, c = rows.get((scene, "penumbra")), rows.get((scene, "cycles"))
    if not p or not c or 1 not in p or 1 not in c:
        continue
    cells = [scene]
    for n in spps:
        if n not in p or n not in c:
            cells.append("–")
            continue
        mp = pixels * (n - 1) / (p[n][0] - p[1][0]) / 1e6 if p[n][0] > p[1][0] else float("nan")
        mc = pixels * (n - 1) / (c[n][0] - c[1][0]) / 1e6 if c[n][0] > c[1][0] else float("nan")
        cells.append(f"{fmt(mp)} / {fmt(mc)} = **{fmt(mp / mc)}×**")
    common = [k for k in p if k in c and k > 1]
    if not common:
        print("| " + " | ".join(cells + ["–"] * 4) + " |")
        continue
    n = max(common)
    tp, tc = pixels * n / p[n][0] / 1e6, pixels * n / c[n][0] / 1e6
    cells.append(f"{fmt(tp)} / {fmt(tc)} = {fmt(tp / tc)}×")
    ep, ec = p[n][1], c[n][1]
    cells.append(f"{ep:.5f} / {ec:.5f}")
    target = max(ep, ec)
    pts_p = [v for k, v in p.items() if k > 1]
    pts_c = [v for k, v in c.items() if k > 1]
    xp, xc = time_to(pts_p, target), time_to(pts_c, target)
    cells.append(f"{fmt(xp)} s / {fmt(xc)} s = **{fmt(xc / xp)}×**")
    mpp = [(t - p[1][0], e) for t, e in pts_p]
    mcc = [(t - c[1][0], e) for t, e in pts_c]
    cells.append(f"**{fmt(time_to(mcc, target) / time_to(mpp, target))}×**")
    print("| " + " | ".join(cells) + " |")
