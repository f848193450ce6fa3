#!/usr/bin/env python3
"""The figures of docs/popping.md from a popping report: the error-jump plot (J against angle) as a
standalone SVG, and the first event's frames before and after (axis | sheet | reference)
with the |after - before| heat maps, tiled into one PNG strip with oiiotool.
Usage: python3 tools/popping_figures.py REPORT_DIR OUT_PREFIX"""
import base64
import os
import re
import subprocess
import sys
import tempfile

report, prefix = sys.argv[1], sys.argv[2]
html = open(os.path.join(report, "report.html"), encoding="utf-8").read()
plots = re.findall(r'<svg class="plot".*?</svg>', html, re.S)
jplot = next((p for p in plots if "Error jump" in p), plots[0])
with open(prefix + "_jump.svg", "w", encoding="utf-8") as f:
    f.write(jplot.replace("<svg ", '<svg xmlns="http://www.w3.org/2000/svg" ', 1))
imgs = re.findall(r'<img class="(frame|heatmap)"[^>]*?src="data:image/png;base64,([^"]+)"[^>]*?'
                  r'alt="event 1 ([^"]+)"', html)
if not imgs:  # attribute order may differ
    imgs = [(c, d, a) for c, a, d in re.findall(
        r'<img class="(frame|heatmap)" alt="event 1 ([^"]+)"[^>]*?src="data:image/png;base64,([^"]+)"', html)]
wanted = ["axis before", "sheet before", "reference before", "axis after", "sheet after",
          "reference after", "axis |after − before|", "sheet |after − before|",
          "reference |after − before|"]
tmp = tempfile.mkdtemp()
files = []
for name in wanted:
    data = next((d for c, d, a in imgs if a == name), None)
    if data is None:
        sys.exit(f"popping_figures: no image '{name}' for event 1 in {report}/report.html")
    path = os.path.join(tmp, f"{len(files)}.png")
    open(path, "wb").write(base64.b64decode(data))
    files.append(path)
subprocess.run(["oiiotool", *files, "--mosaic:pad=4", "3x3", "-o", prefix + "_event.png"], check=True)
print(f"wrote {prefix}_jump.svg and {prefix}_event.png")
