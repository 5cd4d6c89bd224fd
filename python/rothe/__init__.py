"""rothe from Python: scenarios, runs, studies and material points.

A scenario is read with :func:`load` (a file), :func:`loads` (TOML text) or
:func:`from_dict` (a dict), with the command line's variants (``variants``, a dict
group -> option), values (``set``, a dict dotted path -> value, as ``--set``) and
removals (``unset``, a list of dotted paths). It is validated as ``rothe check``
validates it: bad input raises :class:`Error` with the command line's message,
naming the field.

``Scenario.run()`` runs it in memory (``out=None``: nothing is written) or into a
directory (``out=...``: exactly the files of ``rothe run``) and returns a
:class:`Run` with the summary as a dict and the history as NumPy arrays under
``history.csv``'s column names.

    >>> import rothe
    >>> s = rothe.load("examples/benchmarks/two_blocks.toml",
    ...                variants={"concrete": "elastic"},
    ...                set={"meshing.element_size": 0.2, "analysis.t_end": 3e-3})
    >>> run = s.run()
    >>> run.history["E_kin"][-1], run.summary["energy"]["balance_residual_rel"]
"""

from __future__ import annotations

import csv
import json
import math
import os
import shutil
import tempfile
from pathlib import Path
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Union

import numpy as np

from . import _rothe
from ._rothe import Error

__all__ = [
    "Error",
    "Scenario",
    "Run",
    "Modes",
    "load",
    "loads",
    "from_dict",
    "material",
    "study_time",
    "study_mesh",
    "study_tolerance",
    "compare",
    "__version__",
]

__version__ = _rothe.__version__

PathLike = Union[str, "os.PathLike[str]"]


# --- values for `set` -----------------------------------------------------------


def _toml_key(k: str) -> str:
    ok = k and all(c.isalnum() or c in "-_" for c in k)
    return k if ok else json.dumps(k)


def _toml_value(v: Any, field: str) -> str:
    """A Python value as TOML text, as `--set path=value` takes it."""
    if isinstance(v, (bool, np.bool_)):
        return "true" if v else "false"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        x = float(v)
        if math.isnan(x):
            return "nan"
        if math.isinf(x):
            return "inf" if x > 0 else "-inf"
        return repr(x)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, np.ndarray):
        return _toml_value(v.tolist(), field)
    if isinstance(v, Mapping):
        inner = ", ".join(f"{_toml_key(str(k))} = {_toml_value(x, field)}" for k, x in v.items())
        return "{ " + inner + " }" if inner else "{}"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x, field) for x in v) + "]"
    raise Error(f"{field}: a value of type {type(v).__name__} has no TOML form")


def _overrides(variants, set, unset):
    if variants is None:
        variants = {}
    if not isinstance(variants, Mapping):
        raise Error("variants: expected a dict group -> option")
    v = [(str(g), str(o)) for g, o in variants.items()]
    if set is None:
        set = {}
    if not isinstance(set, Mapping):
        raise Error("set: expected a dict dotted.path -> value")
    s = [(str(p), _toml_value(x, str(p))) for p, x in set.items()]
    if unset is None:
        unset = []
    if isinstance(unset, str):
        unset = [unset]
    u = [str(p) for p in unset]
    return v, u, s


def _jsonable(v: Any, field: str = "scenario") -> Any:
    if isinstance(v, Mapping):
        return {str(k): _jsonable(x, f"{field}.{k}") for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_jsonable(x, f"{field}[{i}]") for i, x in enumerate(v)]
    if isinstance(v, np.ndarray):
        return _jsonable(v.tolist(), field)
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (int, np.integer)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        x = float(v)
        if not math.isfinite(x):
            # JSON, which carries the dict to the validation, has no NaN or
            # infinity; no number of a scenario may be one anyway.
            raise Error(f"{field}: {x} is not a finite number")
        return x
    if isinstance(v, (str, os.PathLike)):
        return os.fspath(v)
    raise Error(f"{field}: a value of type {type(v).__name__} has no TOML form")


# --- scenarios --------------------------------------------------------------------


class Scenario:
    """A validated scenario (variants and values applied). Build one with
    :func:`load`, :func:`loads` or :func:`from_dict`."""

    def __init__(self, native: "_rothe.NativeScenario"):
        self._native = native

    def __repr__(self) -> str:
        path = self._native.source()[0]
        return f"<rothe.Scenario {path or '(text)'}>"

    def to_dict(self) -> Dict[str, Any]:
        """The scenario as a dict (variants resolved, values set)."""
        return json.loads(self._native.to_json())

    def to_toml(self) -> str:
        """The scenario as TOML text (variants resolved, values set)."""
        return self._native.to_toml()

    def check(self) -> Dict[str, Any]:
        """What ``rothe check`` prints, as a dict: bodies, nodes, elements, dofs,
        steps, ``dt``, the memory estimate (bytes by part and ``total``), the
        critical step, the scheme, ``rho_inf`` and the contact predictor, warnings,
        materials and contact pairs; ``text`` holds the printed report."""
        return json.loads(self._native.check_json())

    def modes(
        self,
        count: int = 10,
        shift: Optional[float] = None,
        around: Optional[float] = None,
        out: Optional[PathLike] = None,
        backend: str = "faer",
        overwrite: bool = False,
    ) -> "Modes":
        """The ``count`` lowest eigenfrequencies and mode shapes of ``K x = ω² M x``
        (``rothe modes``): shift-invert Lanczos on the runs' factor at the initial,
        elastic state, checked by a Sturm count. ``shift`` (rad²/s², zero or
        negative) moves the Cholesky's shift; ``around`` (Hz) gives the ``count``
        modes nearest that frequency instead (an LDLᵀ inside the spectrum).
        ``out`` also writes ``modes.csv``, ``modes.json``, ``modes.pvd`` and the
        charts there; a directory holding an earlier run's or modal analysis's
        files is refused unless ``overwrite``, as ``rothe modes --overwrite``. Bad
        input raises :class:`Error` naming the option.
        """
        if not isinstance(count, int) or isinstance(count, bool):
            raise Error(f"count: {count!r} is not a whole number of modes")
        if count < 1:
            raise Error("--count: ask for at least one mode")
        _count("count", count, 1)
        info, shapes, files = self._native.modes(
            count,
            None if shift is None else float(shift),
            None if around is None else float(around),
            None if out is None else os.fspath(out),
            str(backend),
            bool(overwrite),
        )
        return Modes(json.loads(info), shapes, [Path(f) for f in files])

    def run(
        self,
        out: Optional[PathLike] = None,
        overwrite: bool = False,
        record_fields: bool = False,
        progress: Union[None, bool, Callable[[Dict[str, Any]], Any]] = None,
        threads: Optional[int] = None,
        backend: str = "faer",
    ) -> "Run":
        """Runs the scenario and returns its :class:`Run`.

        ``out=None`` runs in memory and writes nothing; a directory writes exactly
        the files of ``rothe run`` (an earlier run there is refused unless
        ``overwrite``). ``record_fields`` keeps every step's displacements
        (:meth:`Run.fields`; with ``out``, also ``fields.bin``). ``progress``:
        ``True`` draws the command line's bar on stderr; a callable is called after
        every step with a dict (``step``, ``steps``, ``t``, ``iterations``,
        ``E_kin``, ``E_el``, ``W_ext``, ``D_total``), and a truthy answer stops the
        run cleanly (its summary ``status`` is then ``"stopped"``). ``threads``
        runs it on a pool of that many threads. Ctrl-C stops the run within a
        fraction of a second and raises ``KeyboardInterrupt``; a written run is
        left marked ``failed`` (interrupted) with every file valid.
        """
        callback = progress if callable(progress) else None
        bar = progress is True
        if threads is not None and (not isinstance(threads, int) or threads < 1):
            raise Error(f"threads: {threads!r} is not a positive count")
        _count("threads", threads, 1)
        native = self._native.run(
            None if out is None else os.fspath(out),
            bool(overwrite),
            bool(record_fields),
            bar,
            callback,
            threads,
            str(backend),
        )
        return Run(native)


def load(
    path: PathLike,
    variants: Optional[Mapping[str, str]] = None,
    set: Optional[Mapping[str, Any]] = None,
    unset: Optional[Sequence[str]] = None,
) -> Scenario:
    """Reads and validates a scenario file (mesh files relative to it)."""
    v, u, s = _overrides(variants, set, unset)
    return Scenario(_rothe.scenario(os.fspath(path), "path", None, v, u, s))


def loads(
    text: str,
    variants: Optional[Mapping[str, str]] = None,
    set: Optional[Mapping[str, Any]] = None,
    unset: Optional[Sequence[str]] = None,
    dir: Optional[PathLike] = None,
) -> Scenario:
    """Reads and validates scenario TOML text (mesh files relative to ``dir``,
    default the working directory)."""
    if not isinstance(text, str):
        raise Error("scenario: expected TOML text (str)")
    v, u, s = _overrides(variants, set, unset)
    return Scenario(
        _rothe.scenario(text, "toml", None if dir is None else os.fspath(dir), v, u, s)
    )


def from_dict(
    d: Mapping[str, Any],
    variants: Optional[Mapping[str, str]] = None,
    set: Optional[Mapping[str, Any]] = None,
    unset: Optional[Sequence[str]] = None,
    dir: Optional[PathLike] = None,
) -> Scenario:
    """Validates a scenario given as a dict of the TOML file's tables (the form
    :meth:`Scenario.to_dict` returns)."""
    if not isinstance(d, Mapping):
        raise Error("scenario: expected a dict of tables")
    v, u, s = _overrides(variants, set, unset)
    text = json.dumps(_jsonable(d))
    return Scenario(
        _rothe.scenario(text, "json", None if dir is None else os.fspath(dir), v, u, s)
    )


# --- runs -------------------------------------------------------------------------


class Run:
    """A finished run: ``summary`` (dict, as ``summary.json``), ``history`` (dict
    of 1-D arrays under ``history.csv``'s column names), the mesh, the recorded
    fields and the last state's cell data."""

    def __init__(self, native: "_rothe.NativeRun"):
        self._native = native
        self.summary: Dict[str, Any] = json.loads(native.summary_json())
        self.history: Dict[str, np.ndarray] = dict(native.take_history())
        out = native.out()
        #: The output directory, or None for a run in memory.
        self.out: Optional[Path] = None if out is None else Path(out)

    def __repr__(self) -> str:
        s = self.summary
        return f"<rothe.Run {s.get('status')} {s.get('steps')} steps, t = {s.get('t_end')}>"

    @property
    def status(self) -> str:
        """``completed`` or ``stopped`` (a failed run raises instead)."""
        return self.summary["status"]

    def to_pandas(self):
        """The history as a pandas DataFrame (needs pandas)."""
        try:
            import pandas as pd
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError("Run.to_pandas() needs pandas: pip install pandas") from e
        return pd.DataFrame(self.history)

    @property
    def mesh(self) -> Dict[str, Any]:
        """``coords`` ``(nodes, dim)``, ``cells`` (kind -> ``(m, nodes)`` indices),
        ``cell_blocks`` (kind -> block of each cell), ``node_sets`` (name ->
        node indices)."""
        coords, cells, sets = self._native.mesh()
        return {
            "coords": coords,
            "cells": {k: c for k, c, _ in cells},
            "cell_blocks": {k: b for k, _, b in cells},
            "node_sets": dict(sets),
        }

    def fields(self) -> Optional[np.ndarray]:
        """Every recorded state's displacements ``(steps + 1, dofs)`` (the run's
        ``record_fields=True``), else None."""
        return self._native.fields()

    def displacement(self) -> np.ndarray:
        """The last state's displacements ``(nodes, dim)``."""
        return self._native.displacement()

    def cell_data(self, name: str) -> np.ndarray:
        """A cell field of the last state ``(cells, components)``, cells in block
        order: ``stress`` (Pa; in the plane ``σxx, σyy, σxy`` and three zeros, in
        a solid ``σxx, σyy, σxy, σzz, σyz, σzx``, a bar's axial stress first) for
        every model; ``damage``, ``equivalent_plastic_strain`` and
        ``dissipation_density`` (J/m³) where a model has history. See
        :meth:`cell_names`."""
        v = self._native.cell_data(name)
        if v is None:
            raise Error(f"cell_data: no field `{name}` (this run has: {', '.join(self.cell_names())})")
        return v

    def cell_names(self) -> List[str]:
        """The cell fields :meth:`cell_data` has."""
        return list(self._native.cell_names())

    def stress(self) -> np.ndarray:
        """``cell_data("stress")``."""
        return self.cell_data("stress")

    def damage(self) -> np.ndarray:
        """``cell_data("damage")[:, 0]``."""
        return self.cell_data("damage")[:, 0]


class Modes:
    """Eigenfrequencies and mode shapes (:meth:`Scenario.modes`).

    ``number`` (place in the spectrum, from 1), ``frequency`` (Hz), ``omega``
    (rad/s), ``period`` (s, ``inf`` for a rigid mode), ``rigid`` and ``residual``
    are 1-D arrays, one entry per mode, lowest first; ``effective_mass`` is
    ``(modes, dim)``, each mode's effective modal mass fraction per direction;
    ``shapes`` is ``(modes, nodes, dim)``, each shape ``M``-normalised
    (``φᵀMφ = 1``). ``info`` is ``modes.json`` as a dict (the Sturm check, the
    shift, what the scenario's step does to each mode) and ``files`` what was
    written.
    """

    def __init__(self, info: Dict[str, Any], shapes: np.ndarray, files: List[Path]):
        self.info = info
        rows = info["modes"]
        self.number = np.array([r["index"] for r in rows], dtype=int)
        self.frequency = np.array([r["f_hz"] for r in rows], dtype=float)
        self.omega = np.array([r["omega_rad_s"] for r in rows], dtype=float)
        self.period = np.array(
            [math.inf if r["period_s"] is None else r["period_s"] for r in rows], dtype=float
        )
        self.rigid = np.array([r["rigid"] for r in rows], dtype=bool)
        self.residual = np.array([r["residual"] for r in rows], dtype=float)
        dim = len(info["total_mass_kg"])
        self.effective_mass = np.array(
            [[e["fraction"] for e in r["effective_mass"]] for r in rows], dtype=float
        ).reshape(len(rows), dim)
        self.shapes = shapes.reshape(len(rows), -1, dim)
        self.files = files

    def __len__(self) -> int:
        return len(self.number)

    def __repr__(self) -> str:
        f = ", ".join(f"{x:.4g}" for x in self.frequency[:4])
        more = ", ..." if len(self) > 4 else ""
        return f"<rothe.Modes {len(self)} modes: {f}{more} Hz>"


# --- tables -----------------------------------------------------------------------


def _read_table(path: Path) -> Dict[str, np.ndarray]:
    """A CSV table as a dict of columns: numbers as float arrays (an empty cell or
    ``-`` is NaN), the rest as arrays of str."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        return {}
    header, body = rows[0], rows[1:]
    table: Dict[str, np.ndarray] = {}
    for j, name in enumerate(header):
        col = [r[j] if j < len(r) else "" for r in body]
        try:
            table[name] = np.array([math.nan if x in ("", "-") else float(x) for x in col])
        except ValueError:
            table[name] = np.array(col, dtype=object)
    return table


def _tables(out: Path) -> Dict[str, Dict[str, np.ndarray]]:
    return {p.stem: _read_table(p) for p in sorted(out.glob("*.csv"))}


def material(spec: Union[PathLike, Mapping[str, Any]], out: Optional[PathLike] = None) -> Dict[str, np.ndarray]:
    """The material-point driver (``rothe material``): a file or a dict with
    ``[material]`` and ``[path]``; returns ``material.csv``'s columns as arrays
    (written into ``out`` when given). A dict is kept beside the output as
    ``material.rothe.toml`` (a name rothe owns) once the driver accepted it; no
    file of the user's is replaced."""
    with tempfile.TemporaryDirectory(prefix="rothe-material-") as tmp:
        out_dir = Path(tmp) if out is None else _output_dir(out, "out")
        if isinstance(spec, Mapping):
            # The driver reads a file: the dict is written as TOML in a directory of
            # rothe's own, and copied beside the output only once it ran.
            file = Path(tmp) / MATERIAL_COPY
            file.write_text(_dict_to_toml(_jsonable(spec, "material")))
        else:
            file = Path(spec)
        _rothe.material(os.fspath(file), os.fspath(out_dir))
        if isinstance(spec, Mapping) and out is not None:
            shutil.copyfile(file, out_dir / MATERIAL_COPY)
        return _read_table(out_dir / "material.csv")


#: The name under which :func:`material` keeps a dict given as the material file.
MATERIAL_COPY = "material.rothe.toml"

#: The name under which a study keeps a scenario given as text or a dict.
SCENARIO_COPY = "scenario.rothe.toml"


def _output_dir(out: PathLike, name: str) -> Path:
    """An output directory as given, refusing the empty path (which would write
    into the working directory)."""
    text = os.fspath(out)
    if text == "" or (isinstance(text, bytes) and text == b""):
        raise Error(f"{name}: an empty path; name the output directory ('.' for the working directory)")
    return Path(text)


def _dict_to_toml(d: Mapping[str, Any]) -> str:
    """A dict of tables (and values) as TOML text."""
    lines: List[str] = []
    tables = []
    for k, v in d.items():
        if isinstance(v, Mapping):
            tables.append((k, v))
        else:
            lines.append(f"{_toml_key(k)} = {_toml_value(v, k)}")
    for name, t in tables:
        lines.append(f"[{_toml_key(name)}]")
        for k, v in t.items():
            lines.append(f"{_toml_key(k)} = {_toml_value(v, f'{name}.{k}')}")
    return "\n".join(lines) + "\n"


def _study_source(scenario: Union[PathLike, Scenario], variants, set, unset, out: Path):
    """A file and overrides for a study: a Scenario read from a file keeps its
    file and overrides; one from text or a dict is written to
    ``out/scenario.rothe.toml``, a name rothe owns (its mesh files must then be
    given by absolute paths)."""
    v, u, s = _overrides(variants, set, unset)
    if isinstance(scenario, Scenario):
        path, _dir, _text, sv, su, ss = scenario._native.source()
        if path is None:
            out.mkdir(parents=True, exist_ok=True)
            path = out / SCENARIO_COPY
            Path(path).write_text(scenario.to_toml())
            sv, su, ss = [], [], []
        return os.fspath(path), list(sv) + v, list(su) + u, list(ss) + s
    return os.fspath(scenario), v, u, s


#: The largest count the native module takes (a 64-bit unsigned integer).
_MAX_COUNT = 2**64 - 1


def _count(name: str, value: Any, least: int = 0) -> Any:
    """A whole-number argument checked by name before the native module sees it:
    ``None`` passes; a bool, a float, a negative or an overflowing number raises
    :class:`Error` naming ``name`` (not Python's nameless ``OverflowError``)."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int):
        raise Error(f"{name}: {value!r} is not a whole number")
    if value < least or value > _MAX_COUNT:
        raise Error(f"{name}: {value} is out of range (at least {least}, at most 2^64 - 1)")
    return value


def _study(kind, scenario, variants, set, unset, out, values, halvings, option, jobs, backend):
    halvings = _count("halvings", halvings)
    jobs = _count("jobs", jobs, 1)
    out = _output_dir(out, "out")
    path, v, u, s = _study_source(scenario, variants, set, unset, out)
    markdown, incomplete = _rothe.study(
        kind, path, v, u, s, os.fspath(out), [float(x) for x in values], halvings, option, jobs, backend
    )
    result: Dict[str, Any] = {"markdown": markdown, "incomplete": list(incomplete), "out": out}
    result["tables"] = _tables(out)
    return result


def study_time(
    scenario: Union[PathLike, Scenario],
    out: PathLike,
    h: Optional[Sequence[float]] = None,
    halvings: Optional[int] = None,
    reference_halvings: Optional[int] = None,
    variants=None,
    set=None,
    unset=None,
    jobs: Optional[int] = None,
    backend: str = "faer",
) -> Dict[str, Any]:
    """``rothe study time``: the steps ``h`` (or ``halvings`` of the scenario's
    step) against a reference ``2^reference_halvings`` times finer; runs into
    ``out`` and returns ``markdown``, ``incomplete`` (runs that did not complete)
    and ``tables`` (each CSV the study wrote, as a dict of arrays; the errors and
    observed orders are in ``tables["time_study"]``)."""
    if (h is None) == (halvings is None):
        raise Error("study_time: give either h (a list of steps) or halvings (a count)")
    return _study(
        "time", scenario, variants, set, unset, out, h or [], halvings,
        None if reference_halvings is None else str(_count("reference_halvings", reference_halvings)), jobs, backend,
    )


def study_tolerance(
    scenario: Union[PathLike, Scenario],
    out: PathLike,
    tolerances: Sequence[float],
    fixed_halvings: Optional[int] = None,
    reference_dt: Optional[float] = None,
    variants=None,
    set=None,
    unset=None,
    jobs: Optional[int] = None,
    backend: str = "faer",
) -> Dict[str, Any]:
    """``rothe study tolerance``: an error-controlled scenario (``analysis.adaptive``)
    at each tolerance, beside fixed steps ``dt_max / 2^k`` (``k`` up to
    ``fixed_halvings``, default 6) and a fixed-step reference (``reference_dt``,
    default the ladder's bottom rung); the errors against the steps are in
    ``tables["study"]``; see :func:`study_time` for the rest."""
    return _study(
        "tolerance", scenario, variants, set, unset, out, list(tolerances), _count("fixed_halvings", fixed_halvings),
        None if reference_dt is None else repr(float(reference_dt)), jobs, backend,
    )


def study_mesh(
    scenario: Union[PathLike, Scenario],
    out: PathLike,
    sizes: Sequence[float],
    variants=None,
    set=None,
    unset=None,
    jobs: Optional[int] = None,
    backend: str = "faer",
) -> Dict[str, Any]:
    """``rothe study mesh``: the scenario at each element size; see
    :func:`study_time` for what it returns."""
    return _study("mesh", scenario, variants, set, unset, out, sizes, None, None, jobs, backend)


def compare(
    scenario: Union[PathLike, Scenario],
    out: PathLike,
    implicit_scheme: str = "backward_euler",
    variants=None,
    set=None,
    unset=None,
    backend: str = "faer",
) -> Dict[str, Any]:
    """``rothe compare``: the implicit path (``implicit_scheme``) against the
    explicit one; the ledgers side by side in ``tables["compare"]``."""
    return _study("compare", scenario, variants, set, unset, out, [], None, implicit_scheme, None, backend)
