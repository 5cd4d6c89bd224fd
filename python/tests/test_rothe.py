"""The Python package against the command line and against the physics: the same
validation, the same files bit for bit, a closing ledger, callbacks, interrupts and
threads."""

import csv
import os
import re
import signal
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import rothe

# Benchmark 1, coarse and short: 96 dofs, 3000 steps through the impact.
SMALL = {"meshing.element_size": 0.2, "analysis.t_end": 3e-3, "analysis.vtk_every": 0}


def two_blocks(examples, **kw):
    return rothe.load(
        examples / "benchmarks" / "two_blocks.toml",
        variants={"concrete": "elastic"},
        set={**SMALL, **kw},
    )


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], np.array([[float(x) for x in r] for r in rows[1:]])


def test_load_applies_variants_sets_and_unsets(examples):
    coarse = two_blocks(examples)
    fine = two_blocks(examples, **{"meshing.element_size": 0.1})
    assert coarse.check()["dofs"] == 96
    assert fine.check()["dofs"] > coarse.check()["dofs"]
    d = coarse.to_dict()
    assert d["materials"]["concrete"]["model"] == "elastic"
    assert "variants" not in d
    assert d["analysis"]["t_end"] == 3e-3
    # `unset` removes a key: the step is then the scenario's required one, refused.
    with pytest.raises(rothe.Error, match="analysis.dt"):
        rothe.load(examples / "benchmarks" / "two_blocks.toml", unset=["analysis.dt"])


def test_from_dict_round_trips_with_to_dict(examples):
    s = two_blocks(examples)
    d = s.to_dict()
    again = rothe.from_dict(d, dir=examples / "benchmarks")
    assert again.to_dict() == d
    assert rothe.loads(s.to_toml(), dir=examples / "benchmarks").to_dict() == d
    # NumPy values are taken as their Python values.
    d["analysis"]["dt"] = np.float64(5e-7)
    assert rothe.from_dict(d).check()["dt"] == 5e-7


def test_check_says_what_the_cli_prints(examples, cli):
    s = two_blocks(examples, **{"analysis.scheme": "trapezoidal"})
    c = s.check()
    for key in ["bodies", "dofs", "steps", "dt", "memory", "scheme", "critical_step"]:
        assert key in c, key
    assert c["steps"] == 3000 and c["scheme"] == "trapezoidal"
    assert c["memory"]["total"] > 0
    assert [b["name"] for b in c["bodies"]] == ["concrete", "steel"]
    printed = subprocess.run(
        [cli, "check", examples / "benchmarks" / "two_blocks.toml", "--variant",
         "concrete=elastic"] + sum((["--set", f"{k}={v}"] for k, v in {**SMALL, "analysis.scheme": "trapezoidal"}.items()), []),
        capture_output=True, text=True, check=True,
    ).stdout
    # The memory the machine has free moves between the two calls: left out.
    free = re.compile(r"; [0-9.]+ [kMGT]?B available")
    assert free.sub("", c["text"].strip()) in free.sub("", printed)


def test_a_run_in_memory_closes_its_ledger_and_writes_nothing(examples, tmp_path):
    os.chdir(tmp_path)
    run = two_blocks(examples).run()
    assert run.status == "completed" and run.out is None
    assert list(tmp_path.iterdir()) == []
    h = run.history
    n = run.summary["steps"] + 1
    assert all(len(v) == n for v in h.values())
    # ΔE_kin + ΔE_el + D − W_ext, from the columns, is the residual column and is
    # round-off of the energies.
    d = sum(h[c] for c in h if c.startswith("D_"))
    balance = (h["E_kin"] - h["E_kin"][0]) + (h["E_el"] - h["E_el"][0]) + d - h["W_ext"]
    scale = np.max(np.abs(h["E_kin"]))
    assert np.max(np.abs(balance - h["residual"])) < 1e-9 * scale
    assert np.max(np.abs(h["residual"])) < 1e-9 * scale
    assert h["D_contact"][-1] > 0, "the blocks met"


def test_a_written_run_is_the_cli_run_bit_for_bit(examples, tmp_path, cli):
    scenario = examples / "benchmarks" / "two_blocks.toml"
    sets = {**SMALL, "analysis.vtk_every": 500}
    args = [cli, "run", scenario, "--variant", "concrete=elastic", "--quiet", "--out", tmp_path / "cli"]
    for k, v in sets.items():
        args += ["--set", f"{k}={v}"]
    subprocess.run(args, check=True, capture_output=True)
    s = rothe.load(scenario, variants={"concrete": "elastic"}, set=sets)
    run = s.run(out=tmp_path / "py")
    assert run.out == tmp_path / "py"
    a = (tmp_path / "cli" / "history.csv").read_bytes()
    b = (tmp_path / "py" / "history.csv").read_bytes()
    assert a == b
    assert (tmp_path / "py" / "result.pvd").is_file()
    # The arrays hold the values the file rounds to 13 digits.
    # The arrays hold the values the file rounds: 13 digits for the ledger, 7 for
    # the balance residual, 4 for the iterations' residual.
    header, rows = read_csv(tmp_path / "py" / "history.csv")
    digits = {"t": 1e-9, "residual": 1e-6, "nl_residual": 1e-3}
    for j, name in enumerate(header):
        col = run.history[name]
        assert np.allclose(col, rows[:, j], rtol=digits.get(name, 1e-11), atol=0), name
    # An earlier run is refused unless overwritten, as on the command line.
    with pytest.raises(rothe.Error, match="--overwrite"):
        s.run(out=tmp_path / "py")
    s.run(out=tmp_path / "py", overwrite=True)


def test_fields_mesh_and_cell_data_have_their_shapes(examples):
    s = rothe.load(
        examples / "benchmarks" / "two_blocks.toml",
        variants={"concrete": "mazars_classic"},
        set={**SMALL, "analysis.t_end": 2e-4},
    )
    run = s.run(record_fields=True)
    steps, dofs = run.summary["steps"], run.summary["dofs"]
    f = run.fields()
    assert f.shape == (steps + 1, dofs)
    assert np.array_equal(f[-1], run.displacement().reshape(-1))
    m = run.mesh
    assert m["coords"].shape == (dofs // 2, 2)
    assert sum(len(c) for c in m["cells"].values()) == run.summary["elements"]
    assert "concrete.bottom" in m["node_sets"]
    assert run.stress().shape == (run.summary["elements"], 6)
    assert run.damage().shape == (run.summary["elements"],)
    assert np.all(run.damage() >= 0)
    with pytest.raises(rothe.Error, match="no field `nothing`"):
        run.cell_data("nothing")
    assert two_blocks(examples, **{"analysis.t_end": 1e-5}).run().fields() is None


def test_the_material_driver_gives_the_cli_table(examples, tmp_path, cli):
    file = examples / "materials" / "mazars_tension.toml"
    subprocess.run([cli, "material", file, "--out", tmp_path / "cli"], check=True, capture_output=True)
    table = rothe.material(file, out=tmp_path / "py")
    assert (tmp_path / "cli" / "material.csv").read_bytes() == (tmp_path / "py" / "material.csv").read_bytes()
    header, rows = read_csv(tmp_path / "cli" / "material.csv")
    for j, name in enumerate(header):
        assert np.array_equal(table[name], rows[:, j]), name
    # A dict works too, without an output directory.
    import tomllib  # noqa: PLC0415 (3.11+; the driver file's tables as a dict)

    spec = tomllib.loads(file.read_text())
    again = rothe.material(spec)
    assert np.array_equal(again[header[1]], table[header[1]])


def test_a_time_study_reads_order_two_for_the_trapezoidal_rule(examples, tmp_path):
    r = rothe.study_time(
        examples / "scenarios" / "smooth_cantilever.toml", tmp_path / "study",
        h=[1e-5, 5e-6, 2.5e-6, 1.25e-6], set={"analysis.scheme": "trapezoidal"},
    )
    assert r["incomplete"] == []
    t = r["tables"]["study"]
    assert np.allclose(t["h"], [1e-5, 5e-6, 2.5e-6, 1.25e-6])
    orders = t["order_linear_Linf_L2"][1:]
    assert np.all(np.abs(orders - 2.0) <= 0.1), orders
    assert np.isnan(t["order_linear_Linf_L2"][0])


def test_an_adaptive_run_and_a_tolerance_study(examples, tmp_path):
    # Benchmark 1 coarse, error-controlled: fewer steps than the fixed 1 µs, the
    # summary's account of them, and the tolerance study's table beside fixed steps.
    adaptive = {"analysis.dt": 1.6e-5, "analysis.adaptive.dt_max": 1.6e-5,
                "analysis.adaptive.dt_min": 1e-6}
    run = two_blocks(examples, **adaptive).run()
    s = run.summary
    assert s["steps_accepted"] == s["steps"] < 3000
    assert s["impacts"] == 1 and s["dt_max_used"] == 1.6e-5
    r = rothe.study_tolerance(two_blocks(examples, **adaptive), tmp_path / "tol",
                              tolerances=[1e-2, 1e-3], fixed_halvings=2)
    assert r["incomplete"] == []
    t = r["tables"]["study"]
    assert list(t["run"]) == ["tol0", "tol1", "fixed0", "fixed1", "fixed2"]
    assert t["steps"][1] > t["steps"][0] and np.all(t["err_linear_L2_H1"] > 0)
    with pytest.raises(rothe.Error, match="analysis.adaptive"):
        rothe.study_time(two_blocks(examples, **adaptive), tmp_path / "time", h=[1e-5, 5e-6])


def test_compare_and_a_mesh_study_give_their_tables(examples, tmp_path):
    c = rothe.compare(examples / "benchmarks" / "two_blocks.toml", tmp_path / "cmp",
                      implicit_scheme="trapezoidal", set={**SMALL, "analysis.t_end": 1e-3})
    assert c["incomplete"] == []
    t = c["tables"]["compare"]
    row = list(t["line"]).index("balance residual [J]")
    assert abs(t["implicit"][row]) < 1e-6 * t["implicit"][list(t["line"]).index("E_kin0 [J]")]
    assert np.all(np.isfinite(t["explicit"][:row]))
    m = rothe.study_mesh(two_blocks(examples, **{"analysis.t_end": 1e-4}), tmp_path / "mesh",
                         sizes=[0.2, 0.1])
    assert m["incomplete"] == []
    assert list(m["tables"]["study"]["size"]) == [0.2, 0.1]
    assert m["tables"]["study"]["dofs"][1] > m["tables"]["study"]["dofs"][0]


@pytest.mark.parametrize(
    "make, field",
    [
        (lambda ex: rothe.load(ex / "nothing.toml"), "nothing.toml"),
        (lambda ex: rothe.load(ex / "benchmarks" / "two_blocks.toml", set={"analysis.nothing": 1}), "analysis.nothing"),
        (lambda ex: rothe.load(ex / "benchmarks" / "two_blocks.toml", set={"analysis.dt": "soon"}), "analysis.dt"),
        (lambda ex: rothe.load(ex / "benchmarks" / "two_blocks.toml", variants={"concrete": "glass"}), "concrete"),
        (lambda ex: rothe.loads(two_blocks(ex).to_toml().replace("t_end = 0.003", "t_end = -1.0")), "analysis.t_end"),
        (lambda ex: rothe.loads("[analysis\n"), "line 1"),
        (lambda ex: rothe.from_dict({"analysis": {"t_end": 1.0, "dt": object()}}), "analysis.dt"),
        (lambda ex: rothe.from_dict([1, 2]), "scenario"),
        (lambda ex: rothe.load(ex / "benchmarks" / "two_blocks.toml", set=[1]), "set"),
        (lambda ex: two_blocks(ex).run(backend="lapack"), "backend"),
        (lambda ex: two_blocks(ex).run(threads=0), "threads"),
        (lambda ex: rothe.material({"material": {"model": "elastic"}}), "material"),
        (lambda ex: rothe.study_time(ex / "scenarios" / "smooth_cantilever.toml", "/tmp/x"), "study_time"),
    ],
)
def test_bad_input_raises_rothe_error_naming_the_field(examples, make, field):
    with pytest.raises(rothe.Error) as e:
        make(examples)
    assert field in str(e.value)
    assert isinstance(e.value, ValueError)


def test_a_progress_callback_stops_the_run_cleanly(examples, tmp_path):
    seen = []

    def progress(info):
        seen.append(info)
        return info["step"] >= 250

    run = two_blocks(examples).run(out=tmp_path / "r", progress=progress)
    assert run.status == "stopped" and run.summary["steps"] == 250
    assert [i["step"] for i in seen] == list(range(1, 251))
    assert set(seen[0]) == {"step", "steps", "t", "iterations", "E_kin", "E_el", "W_ext", "D_total"}
    assert len(run.history["t"]) == 251
    # Its files say so and hold the 250 steps.
    import json

    summary = json.loads((tmp_path / "r" / "summary.json").read_text())
    assert summary["status"] == "stopped" and summary["steps"] == 250
    assert len((tmp_path / "r" / "history.csv").read_text().splitlines()) == 252
    # An exception in the callback stops the run and reaches the caller.
    with pytest.raises(ZeroDivisionError):
        two_blocks(examples).run(progress=lambda info: 1 / 0)


def test_ctrl_c_stops_a_long_run_and_marks_it(examples, tmp_path):
    long = rothe.load(
        examples / "benchmarks" / "two_blocks.toml",
        variants={"concrete": "elastic"},
        set={"analysis.t_end": 10.0, "analysis.vtk_every": 0},
    )
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    t0 = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        long.run(out=tmp_path / "long")
    assert time.monotonic() - t0 < 5.0
    import json

    summary = json.loads((tmp_path / "long" / "summary.json").read_text())
    assert summary["status"] == "failed" and "interrupted" in summary["error"]
    rows = (tmp_path / "long" / "history.csv").read_text().splitlines()
    assert len(rows) - 2 == summary["steps"] > 0


def test_two_runs_on_two_threads_give_their_own_results(examples):
    a, b = two_blocks(examples), two_blocks(examples, **{"analysis.scheme": "trapezoidal"})
    alone = [a.run().history, b.run().history]
    out = [None, None]

    def go(i, s):
        out[i] = s.run().history

    threads = [threading.Thread(target=go, args=(i, s)) for i, s in enumerate([a, b])]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for mine, ref in zip(out, alone):
        for k in ref:
            assert np.array_equal(mine[k], ref[k]), k
    assert not np.array_equal(out[0]["E_kin"], out[1]["E_kin"])


def test_a_thousand_small_runs_keep_the_memory_bounded(examples):
    s = two_blocks(examples, **{"analysis.t_end": 2e-5})

    def rss_kib():
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
        pytest.skip("no /proc/self/status")

    for _ in range(100):
        s.run()
    before = rss_kib()
    for _ in range(1000):
        s.run()
    grown = rss_kib() - before
    assert grown < 20_000, f"RSS grew by {grown} KiB over 1000 runs"


def test_threads_sets_the_pool_and_gives_the_same_history(examples):
    s = two_blocks(examples)
    one = s.run(threads=1).history
    two = s.run(threads=2).history
    for k in one:
        assert np.array_equal(one[k], two[k]), k


def test_to_pandas(examples):
    pd = pytest.importorskip("pandas")
    df = two_blocks(examples, **{"analysis.t_end": 1e-4}).run().to_pandas()
    assert isinstance(df, pd.DataFrame) and "D_num" in df.columns and len(df) == 101


AXIAL_BAR = """
[analysis]
t_end = 1.0e-4
dt = 1.0e-6
[materials.steel]
model = "elastic"
E = 210e9
nu = 0.0
rho = 7850.0
[[bodies]]
name = "bar"
material = "steel"
thickness = 0.05
mesh = { kind = "rectangle", size = [1.0, 0.05], divisions = [80, 1] }
[[supports]]
set = "bar.left"
fix = ["x"]
[[supports]]
set = "bar.all"
fix = ["y"]
"""


def test_modes_of_an_axial_bar_match_its_closed_form_and_the_command_line(tmp_path, cli):
    # A fixed-free bar: f_k = (2k − 1) c / (4L), from above with consistent mass.
    s = rothe.loads(AXIAL_BAR)
    m = s.modes(count=3)
    c = (210e9 / 7850.0) ** 0.5
    exact = np.array([(2 * k - 1) * c / 4.0 for k in (1, 2, 3)])
    assert len(m) == 3 and list(m.number) == [1, 2, 3]
    assert np.all(m.frequency > exact) and np.all(m.frequency / exact - 1 < 1e-3)
    assert np.allclose(m.omega, 2 * np.pi * m.frequency)
    assert m.shapes.shape == (3, 162, 2) and not m.rigid.any()
    # The first axial mode carries 8/π² of the bar's mass along x; the fraction is
    # of the mass on the free dofs, ι_fᵀ M_ff ι_f = M (1 − 2/(3n)) with consistent
    # mass and the end column of n = 80 elements fixed; none along y (fixed).
    assert abs(m.effective_mass[0, 0] - (8 / np.pi**2) / (1 - 2 / 240)) < 2e-4
    assert np.all(m.effective_mass[:, 1] == 0.0)
    assert m.info["sturm"]["eigenvalues_counted"] >= 3
    # The modes nearest a frequency, numbered in the spectrum; files as the CLI's.
    near = s.modes(count=1, around=float(exact[1]), out=tmp_path / "py")
    assert list(near.number) == [2] and abs(near.frequency[0] / m.frequency[1] - 1) < 1e-9
    assert {f.name for f in near.files} >= {"modes.csv", "modes.json", "modes.pvd"}
    scenario = tmp_path / "bar.toml"
    scenario.write_text(AXIAL_BAR)
    subprocess.run(
        [cli, "modes", scenario, "--count", "1", "--around", repr(float(exact[1])),
         "--out", tmp_path / "cli"],
        check=True, capture_output=True,
    )
    assert (tmp_path / "py" / "modes.csv").read_bytes() == (tmp_path / "cli" / "modes.csv").read_bytes()
    for bad, field in [(dict(count=0), "--count"), (dict(around=-1.0), "--around"),
                       (dict(shift=5.0), "--shift"), (dict(backend="x"), "backend")]:
        with pytest.raises(rothe.Error, match=field):
            s.modes(**bad)


def test_the_summary_says_whether_energy_was_created(examples):
    # theory/energy.md, "No energy created": backward Euler never gains; the
    # check's excess is what the history's columns give, E_kin + E_el + the physical
    # lines - (E_kin0 + E_el0 + W_ext), at its largest over the run.
    run = two_blocks(examples).run()
    c = run.summary["checks"]["no_energy_created"]
    assert c["holds"] and c["lhs"] == 0.0 and run.summary["checks"]["energy_created_at_step"] == 0
    h = run.history
    physical = sum(h[k] for k in h if k.startswith("D_") and k != "D_num")
    excess = (h["E_kin"] - h["E_kin"][0]) + (h["E_el"] - h["E_el"][0]) + physical - h["W_ext"]
    assert np.max(excess) <= c["tolerance"]
