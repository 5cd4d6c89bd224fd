"""A time study from Python: the smoothly loaded cantilever by backward Euler and
by the trapezoidal rule, the tip's error against h in a log-log figure, and the
observed orders (1 and 2) printed.

    .venv/bin/python examples/python/time_study.py [OUT]   # writes OUT/time_study.png
"""

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import rothe  # noqa: E402

here = Path(__file__).resolve().parent
scenario = here.parent / "scenarios" / "smooth_cantilever.toml"
out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/python_time_study")
steps = [1e-5, 5e-6, 2.5e-6, 1.25e-6]

fig, ax = plt.subplots(figsize=(6, 4.5))
for scheme in ["backward_euler", "trapezoidal"]:
    study = rothe.study_time(scenario, out / scheme, h=steps, set={"analysis.scheme": scheme})
    t = study["tables"]["study"]
    err = t["err_linear_Linf_L2"]
    print(f"{scheme:>15}: orders {np.round(t['order_linear_Linf_L2'][1:], 3)}")
    ax.loglog(t["h"], err, "o-", label=scheme.replace("_", " "))
ax.set_xlabel("h [s]")
ax.set_ylabel("error in L∞(L²) [m]")
ax.set_title("Smoothly loaded cantilever: order 1 and order 2")
ax.grid(True, which="both", alpha=0.3)
ax.legend()
fig.tight_layout()
out.mkdir(parents=True, exist_ok=True)
fig.savefig(out / "time_study.png", dpi=120)
print(f"wrote {out / 'time_study.png'}")
