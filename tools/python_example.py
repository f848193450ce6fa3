#!/usr/bin/env python3
# splat from Python (docs/python.md): load a volume, render it with the three renderers,
# compare them, find popping on a sweep and plot the error series. ctest runs it (python.example).
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt
import nibabel as nib
import numpy as np

import splat

out = Path(sys.argv[1] if len(sys.argv) > 1 else "splat-python")
out.mkdir(parents=True, exist_ok=True)

# The volume: nibabel's array [x, y, z] with its affine, which is what splat.load reads from
# the file. Without mricron-data's ch2, a synthetic head.
ch2 = Path("/usr/share/mricron/templates/ch2.nii.gz")
if ch2.exists():
    volume = splat.from_nibabel(nib.load(ch2))
    assert np.array_equal(volume.array, splat.load(str(ch2)).array)
    tf = "mri-head"
else:
    volume = splat.load("synthetic:phantom:96")
    tf = "ct-bone"
print(volume, "values", volume.value_range)

# One Scene (classified once), three renderers; keywords are the CLI's options.
scene = splat.Scene(volume, tf=tf, size=(160, 160), azimuth=30, elevation=15)
images = {r: scene.render(renderer=r) for r in ("axis", "sheet", "reference")}
for name, image in images.items():
    splat.write_image(str(out / f"{name}.png"), image)
    m = splat.compare(image, images["reference"])
    print(f"{name:9s} rmse {m['rmse']:.4f}  psnr {m['psnr']:6.2f}  flip {m['flip']:.4f}")

# Popping: an azimuth sweep with every renderer, events refined by bisection.
pop = splat.popping(volume, tf=tf, size=(48, 48), from_=40, to=46, step=1, refine=3)
pop.write_report(str(out / "popping"))  # report.html, metrics.csv, summary.json
for e in pop.events:
    print(f"event ({e['renderer']}) at {e['refined_angle']:.3f} deg, slope {e['refined_slope']:.2f}")

fig, ax = plt.subplots(figsize=(6, 3.5))
for name, series in pop.series.items():
    if name != "reference":
        ax.plot(pop.angles, series["e"], marker="o", label=name)
ax.set_xlabel("azimuth (degrees)")
ax.set_ylabel("RMS error against the reference")
ax.legend()
fig.tight_layout()
fig.savefig(out / "error.png", dpi=100)
print("wrote", out / "error.png")
