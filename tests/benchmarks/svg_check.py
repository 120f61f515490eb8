#!/usr/bin/python3
"""Checks a penumbra-bench chart (benchmarks/chart.h) as an SVG reader sees it.

    svg_check.py CHART.svg

Parses the file with xml.etree and checks, per panel: y-axis ticks evenly spaced at 1, 2 or 5 x
10^k, covering every bar's min..max; a grid line per tick; a y label with a unit in brackets; and
per bar, that the bar top and the error bar's ends sit at the median, max and min of its tooltip on
the axis the ticks define. Also the caption's machine and settings. Prints "ok: ..." and exits 0,
or prints what is wrong and exits 1.
"""
import math
import re
import sys
import xml.etree.ElementTree as ET

NS = "{http://www.w3.org/2000/svg}"
TOL = 0.05  # px: coordinates are written with two decimals


def fail(msg):
    print("svg_check: " + msg)
    sys.exit(1)


def by_class(elem, tag, cls):
    return [e for e in elem.iter(NS + tag) if cls in (e.get("class") or "").split()]


def check_ticks(values, where):
    if len(values) < 2:
        fail(f"{where}: fewer than two ticks")
    step = values[1] - values[0]
    if not step > 0:
        fail(f"{where}: ticks not increasing: {values}")
    for a, b in zip(values, values[1:]):
        if abs((b - a) - step) > 1e-9 * max(abs(step), 1e-300) + 1e-12 * max(abs(a), abs(b)):
            fail(f"{where}: ticks not evenly spaced: {values}")
    mantissa = step / 10 ** math.floor(math.log10(step) + 1e-12)
    if not any(abs(mantissa - m) < 1e-6 for m in (1, 2, 5)):
        fail(f"{where}: tick step {step} is not 1, 2 or 5 x 10^k")
    for v in values:
        if abs(v / step - round(v / step)) > 1e-6:
            fail(f"{where}: tick {v} is not a multiple of the step {step}")
    return step


def main():
    if len(sys.argv) != 2:
        fail("usage: svg_check.py CHART.svg")
    try:
        root = ET.parse(sys.argv[1]).getroot()
    except ET.ParseError as e:
        fail(f"{sys.argv[1]}: not well-formed XML: {e}")
    if root.tag != NS + "svg":
        fail(f"root element is {root.tag}, not an SVG <svg>")
    for attr in ("width", "height"):
        if not float(root.get(attr, "0")) > 0:
            fail(f"<svg> has no positive {attr}")
    if len((root.get("viewBox") or "").split()) != 4:
        fail("<svg> has no viewBox")

    panels = by_class(root, "g", "panel")
    if not panels:
        fail("no panels")
    bars_total = 0
    for pi, panel in enumerate(panels):
        where = f"panel {pi + 1}"
        ticks = []
        for tick in by_class(panel, "g", "tick"):
            line, text = tick.find(NS + "line"), tick.find(NS + "text")
            if line is None or text is None:
                fail(f"{where}: a tick without its line and label")
            ticks.append((float(text.text), float(line.get("y1"))))
        ticks.sort()
        values = [v for v, _ in ticks]
        check_ticks(values, where)
        grid = by_class(panel, "g", "grid")
        if len(grid) != 1 or len(grid[0].findall(NS + "line")) != len(ticks):
            fail(f"{where}: not one grid line per tick")
        (v0, y0), (v1, y1) = ticks[0], ticks[-1]
        if not y1 < y0:
            fail(f"{where}: the y axis does not grow upwards")

        def y_of(v):
            return y0 + (v - v0) * (y1 - y0) / (v1 - v0)

        ylabels = [t for t in by_class(panel, "text", "axis-label")
                   if (t.get("transform") or "").startswith("rotate(-90")]
        if len(ylabels) != 1 or not re.fullmatch(r".+ \(.+\)", ylabels[0].text or ""):
            fail(f"{where}: no y label with a unit in brackets")
        for bar in by_class(panel, "g", "bar"):
            title = bar.find(NS + "title")
            m = re.search(r"median (\S+) .*\(min (\S+), max (\S+)\)$", title.text if title is not None else "")
            if not m:
                fail(f"{where}: a bar without its median, min and max")
            median, lo, hi = (float(x) for x in m.groups())
            if not (lo <= median <= hi):
                fail(f"{where}: {title.text}: median outside min..max")
            if lo < values[0] - 1e-12 or hi > values[-1] + 1e-12:
                fail(f"{where}: {title.text}: outside the ticks {values[0]}..{values[-1]}")
            rect = bar.find(NS + "rect")
            spread = [e for e in bar.findall(NS + "line") if e.get("class") == "spread"]
            caps = [e for e in bar.findall(NS + "line") if e.get("class") == "cap"]
            if rect is None or len(spread) != 1 or len(caps) != 2:
                fail(f"{where}: {title.text}: bar without a rect, an error bar and two caps")
            if abs(float(rect.get("y")) - min(y_of(median), y_of(0))) > TOL:
                fail(f"{where}: {title.text}: bar top not at the median")
            top, bottom = float(spread[0].get("y1")), float(spread[0].get("y2"))
            if abs(top - y_of(hi)) > TOL or abs(bottom - y_of(lo)) > TOL:
                fail(f"{where}: {title.text}: error bar {top}..{bottom} is not min..max "
                     f"({y_of(hi):.2f}..{y_of(lo):.2f})")
            for cap in caps:
                if min(abs(float(cap.get("y1")) - top), abs(float(cap.get("y1")) - bottom)) > TOL:
                    fail(f"{where}: {title.text}: a cap not at an end of the error bar")
            bars_total += 1

    caption = " ".join(t.text or "" for g in by_class(root, "g", "caption") for t in g.iter(NS + "text"))
    for needed in ("Machine:", "RAM", "spp", "threads", "error bars"):
        if needed not in caption:
            fail(f"the caption does not say '{needed}': {caption!r}")
    print(f"ok: {len(panels)} panels, {bars_total} bars")


if __name__ == "__main__":
    main()
