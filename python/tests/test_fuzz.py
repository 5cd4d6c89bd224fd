"""Fuzzing the Python front end: example scenarios as dicts, mutated (numbers
scaled a little, or replaced by zero, negatives, huge values, NaN, infinities,
strings, lists, None; keys removed; tables emptied), then validated, checked and run for a few steps in
memory; and the API's own arguments given wrong types and out-of-range values.
Every outcome must be a result or a ``rothe.Error`` with a message: never a panic
(pyo3's ``PanicException``), never another exception type, never a non-finite
number in a completed run's ledger. Seeded, so a failure repeats."""

import math
import random

import pytest

import rothe

SCENARIOS = [
    (
        "benchmarks/two_blocks.toml",
        {"concrete": "elastic"},
        {"meshing.element_size": 0.2, "analysis.t_end": 3e-4},
    ),
    ("contact/incline.toml", {}, {}),
    ("scenarios/smooth_cantilever.toml", {}, {}),
    ("solid/cube_drop.toml", {}, {"analysis.adaptive.tolerance": 1e-2}),
]

BAD_NUMBERS = [0, -1, -1e300, 1e300, 1e-300, math.nan, math.inf, -math.inf, 2**70]
BAD_VALUES = ["", "x", [], [1.0], None, {}, True]


def leaves(d, path=()):
    """Every (path, value) of a nested dict and list."""
    if isinstance(d, dict):
        for k, v in d.items():
            yield from leaves(v, path + (k,))
    elif isinstance(d, list):
        for i, v in enumerate(d):
            yield from leaves(v, path + (i,))
    else:
        yield path, d


def tables(d, path=()):
    """Every path of a table (dict) below the top."""
    if isinstance(d, dict):
        for k, v in d.items():
            if isinstance(v, dict):
                yield path + (k,)
            yield from tables(v, path + (k,))
    elif isinstance(d, list):
        for i, v in enumerate(d):
            yield from tables(v, path + (i,))


def at(d, path):
    for k in path[:-1]:
        d = d[k]
    return d, path[-1]


def mutate(d, rng):
    """One mutation of the dict `d`, in place; what was done, for the message."""
    kind = rng.choice(["scale", "scale", "number", "number", "value", "remove", "empty"])
    if kind == "scale":
        paths = [p for p, v in leaves(d) if isinstance(v, float)]
        p = rng.choice(paths)
        parent, k = at(d, p)
        parent[k] *= rng.choice([0.5, 0.9, 1.1, 2.0])
        return f"{'.'.join(map(str, p))} scaled to {parent[k]!r}"
    if kind in ("number", "value"):
        paths = [p for p, v in leaves(d) if kind == "value" or isinstance(v, (int, float))]
        if not paths:
            return "nothing"
        p = rng.choice(paths)
        new = rng.choice(BAD_NUMBERS if kind == "number" else BAD_VALUES)
        parent, k = at(d, p)
        parent[k] = new
        return f"{'.'.join(map(str, p))} = {new!r}"
    if kind == "remove":
        paths = [p for p, _ in leaves(d) if isinstance(p[-1], str)]
        p = rng.choice(paths)
        parent, k = at(d, p)
        del parent[k]
        return f"removed {'.'.join(map(str, p))}"
    paths = list(tables(d))
    p = rng.choice(paths)
    parent, k = at(d, p)
    parent[k] = {}
    return f"emptied {'.'.join(map(str, p))}"


def exercise(d, base, what, backend):
    """Validate, check and run a few steps of `d` on `backend`: a result or a
    rothe.Error (a backend this build lacks is refused by name)."""
    try:
        s = rothe.from_dict(d, dir=base)
        plan = s.check()
        assert plan["steps"] >= 1, what
        if plan["steps"] > 400 or plan["dofs"] > 3000:
            return "checked"
        short = rothe.from_dict(
            s.to_dict(), set={"analysis.vtk_every": 0}, dir=base
        )
        run = short.run(backend=backend)
        if run.status == "completed":
            energy = run.summary["energy"]
            for k in ("kinetic", "elastic", "external_work", "balance_residual"):
                assert math.isfinite(energy[k]), f"{what}: {k} = {energy[k]}"
        return "ran"
    except rothe.Error as e:
        assert str(e).strip(), f"{what}: an empty message"
        return "refused"


@pytest.mark.parametrize("file,variants,sets", SCENARIOS)
def test_mutated_scenarios_run_or_are_refused_by_name(examples, file, variants, sets):
    rng = random.Random(f"rothe-fuzz-{file}")
    base = (examples / file).parent
    source = rothe.load(examples / file, variants=variants, set=sets).to_dict()
    outcomes = {}
    for case in range(40):
        d = rothe.from_dict(source, dir=base).to_dict()
        what = "; ".join(mutate(d, rng) for _ in range(rng.randint(1, 2)))
        try:
            o = exercise(d, base, what, rng.choice(["faer", "faer", "cholmod", "mumps"]))
        except AssertionError:
            raise
        except BaseException as e:  # a panic is a BaseException under pyo3
            pytest.fail(f"{file} case {case} ({what}): {type(e).__name__}: {e}")
        outcomes[o] = outcomes.get(o, 0) + 1
    print(file, outcomes)
    # The campaign reaches both sides: refusals and files that still run.
    assert outcomes.get("refused", 0) > 0, outcomes
    assert outcomes.get("ran", 0) + outcomes.get("checked", 0) > 0, outcomes


def test_bad_arguments_are_refused_by_name(examples, tmp_path):
    s = rothe.load(
        examples / "contact" / "incline.toml", set={"analysis.t_end": 2e-3}
    )
    calls = {
        "threads": lambda v: s.run(threads=v),
        "backend": lambda v: s.run(backend=v),
        "count": lambda v: s.modes(count=v),
        "halvings": lambda v: rothe.study_time(
            examples / "contact" / "incline.toml", halvings=v, out=tmp_path / "st"
        ),
    }
    for name, call in calls.items():
        for v in [-1, 2**70, 1.5, math.nan, "two"] + ([] if name == "halvings" else [0]):
            try:
                call(v)
            except rothe.Error as e:
                assert str(e).strip()
                continue
            except BaseException as e:
                pytest.fail(f"{name}={v!r}: {type(e).__name__}: {e}")
            pytest.fail(f"{name}={v!r} was accepted")
