"""Modal analysis from Python: the cantilever's lowest modes, the damping each
implicit scheme gives them at the scenario's step, and the first two shapes drawn
over the mesh.

    .venv/bin/python examples/python/modes.py [OUT]   # writes OUT/shapes.png
"""

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import rothe  # noqa: E402

here = Path(__file__).resolve().parent
path = here.parent / "scenarios" / "cantilever.toml"
out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/python_modes")
s = rothe.load(path)
m = s.modes(count=6, out=out)
print(m)
print(f"Sturm check: {m.info['sturm']['eigenvalues_counted']} eigenvalues counted, all found")
print(" mode     f (Hz)  x mass  y mass  BE damping  GA damping  (at dt)")
for i, row in enumerate(m.info["modes"]):
    print(
        f"{m.number[i]:>5} {m.frequency[i]:10.2f} {m.effective_mass[i, 0]:7.4f} "
        f"{m.effective_mass[i, 1]:7.4f} {row['backward_euler']['damping_ratio']:11.2e} "
        f"{row['generalized_alpha']['damping_ratio']:11.2e}"
    )

# The node coordinates from a one-step run of the same scenario.
dt = s.to_dict()["analysis"]["dt"]
xy = rothe.load(path, set={"analysis.t_end": dt}).run().mesh["coords"]
fig, axes = plt.subplots(2, 1, figsize=(7, 4.5), sharex=True)
for ax, k in zip(axes, range(2)):
    shape = m.shapes[k] / abs(m.shapes[k]).max()
    scale = 0.1 * (xy[:, 0].max() - xy[:, 0].min())
    ax.plot(xy[:, 0], xy[:, 1], ".", color="0.7", ms=2, label="undeformed")
    ax.plot(xy[:, 0] + scale * shape[:, 0], xy[:, 1] + scale * shape[:, 1], ".", ms=2,
            label=f"mode {m.number[k]}: {m.frequency[k]:.1f} Hz")
    ax.set_aspect("equal")
    ax.legend(loc="upper left", fontsize=8)
axes[-1].set_xlabel("x [m]")
fig.tight_layout()
out.mkdir(parents=True, exist_ok=True)
fig.savefig(out / "shapes.png", dpi=150)
print(f"wrote {out / 'shapes.png'} and rothe modes' files in {out}")
