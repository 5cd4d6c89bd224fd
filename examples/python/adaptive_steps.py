"""Error-controlled steps on the paper's benchmark 1, from Python: the step size the
run chose against time (log scale) under the contact force, beside the fixed 1 µs
run's probe, and the summary's account of the steps.

    .venv/bin/python examples/python/adaptive_steps.py [OUT]   # writes OUT/adaptive_steps.png
"""

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import rothe  # noqa: E402

here = Path(__file__).resolve().parent
scenario = here.parent / "benchmarks" / "two_blocks.toml"
out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/python_adaptive")
sets = {"analysis.vtk_every": 0, "analysis.t_end": 4e-3}

adaptive = rothe.load(scenario, variants={"steps": "adaptive"}, set=sets).run()
fixed = rothe.load(scenario, set=sets).run()
s = adaptive.summary
print(
    f"error-controlled: {s['steps_accepted']} steps ({s['steps_rejected']} taken back), "
    f"h from {s['dt_min_used']:.3g} to {s['dt_max_used']:.3g} s, first contact at "
    f"{1e3 * s['first_impact_t']:.5f} ms; fixed 1 µs: {fixed.summary['steps']} steps"
)

h = adaptive.history
t = h["t"]
fig, (ax1, ax2, ax3) = plt.subplots(3, 1, figsize=(7, 7.5), sharex=True)
ax1.semilogy(1e3 * t[1:], np.diff(t), ".", markersize=2)
ax1.set_ylabel("step h [s]")
ax1.set_title("Benchmark 1, error-controlled (tolerance 1e-4)")
ax2.plot(1e3 * t, 1e-3 * h["impact_force"], label="error-controlled")
ax2.plot(1e3 * fixed.history["t"], 1e-3 * fixed.history["impact_force"], "--", label="fixed 1 µs")
ax2.set_ylabel("contact force [kN]")
ax2.legend()
ax3.plot(1e3 * t, 1e3 * h["probe_uy"], label="error-controlled")
ax3.plot(1e3 * fixed.history["t"], 1e3 * fixed.history["probe_uy"], "--", label="fixed 1 µs")
ax3.set_ylabel("probe u_y [mm]")
ax3.set_xlabel("t [ms]")
for ax in (ax1, ax2, ax3):
    ax.grid(True, which="both", alpha=0.3)
fig.tight_layout()
out.mkdir(parents=True, exist_ok=True)
fig.savefig(out / "adaptive_steps.png", dpi=120)
print(f"wrote {out / 'adaptive_steps.png'}")
