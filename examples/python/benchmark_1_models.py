"""The paper's benchmark 1 (two blocks) with each concrete model, from Python:
one run per model in memory, the ledger at the end as a pandas table relative to
the initial kinetic energy, and the probe's peak deflection.

    .venv/bin/python examples/python/benchmark_1_models.py [--coarse]
"""

import sys
from pathlib import Path

import pandas as pd

import rothe

here = Path(__file__).resolve().parent
scenario = here.parent / "benchmarks" / "two_blocks.toml"
coarse = "--coarse" in sys.argv
sets = {"analysis.vtk_every": 0}
if coarse:
    sets |= {"meshing.element_size": 0.2, "analysis.t_end": 4e-3}

rows = []
for model in ["elastic", "kelvin_voigt", "mazars", "rankine_hill"]:
    run = rothe.load(scenario, variants={"concrete": model}, set=sets).run()
    h = run.history
    e0 = run.summary["energy"]["kinetic_0"]
    line = {"model": model}
    for c in ["D_viscous", "D_damage", "D_plastic", "D_contact", "D_num"]:
        line[c] = h[c][-1] / e0
    line["peak [mm]"] = 1e3 * abs(h["probe_uy"]).max()
    line["balance / E_kin0"] = run.summary["energy"]["balance_residual_rel"]
    rows.append(line)

table = pd.DataFrame(rows).set_index("model")
pd.set_option("display.float_format", lambda x: f"{x:.4g}")
pd.set_option("display.width", 200)
pd.set_option("display.max_columns", None)
print(table)
