"""Nothing a user wrote is replaced, no directory takes two writers, and every
argument out of range is refused by its name (README "From Python")."""

import threading
import tomllib

import pytest

import rothe

from test_rothe import AXIAL_BAR

# The axial bar of the modes test, 20 steps.
BAR = AXIAL_BAR.replace("t_end = 1.0e-4", "t_end = 2.0e-5\nvtk_every = 0")


def test_an_empty_output_path_is_refused_and_writes_nothing(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "vtk").mkdir()
    (tmp_path / "vtk" / "mine.txt").write_text("mine")
    s = rothe.loads(BAR)
    for call in (lambda: s.run(out="", overwrite=True), lambda: s.modes(count=1, out="")):
        with pytest.raises(rothe.Error, match="empty"):
            call()
    with pytest.raises(rothe.Error, match="out"):
        rothe.study_time(s, "", halvings=1)
    assert (tmp_path / "vtk" / "mine.txt").read_text() == "mine"
    assert not (tmp_path / "summary.json").exists()


def test_a_material_dict_never_replaces_the_users_file(examples, tmp_path):
    (tmp_path / "material.toml").write_text("# mine\n")
    spec = tomllib.loads((examples / "materials" / "mazars_tension.toml").read_text())
    bad = {**spec, "material": {**spec["material"], "E": -1.0}}
    with pytest.raises(rothe.Error):
        rothe.material(bad, out=tmp_path)
    assert not (tmp_path / rothe.MATERIAL_COPY).exists(), "a refused dict was kept"
    rothe.material(spec, out=tmp_path)
    assert (tmp_path / "material.toml").read_text() == "# mine\n"
    assert tomllib.loads((tmp_path / rothe.MATERIAL_COPY).read_text()) == spec


def test_a_study_of_a_text_scenario_keeps_the_users_scenario(tmp_path):
    out = tmp_path / "study"
    out.mkdir()
    (out / "scenario.toml").write_text("# mine\n")
    rothe.study_time(rothe.loads(BAR), out, halvings=1)
    assert (out / "scenario.toml").read_text() == "# mine\n"
    assert (out / rothe.SCENARIO_COPY).exists()


def test_two_threads_into_one_directory_do_not_mix(tmp_path):
    # One holds the directory; the other is refused by name (or, when the first
    # already finished, refused for the earlier run it finds): never two
    # summaries' worth of files in one place.
    s = rothe.loads(BAR.replace("t_end = 2.0e-5", "t_end = 2.0e-3"))
    errors, done = [], []

    def run():
        try:
            done.append(s.run(out=tmp_path / "o"))
        except rothe.Error as e:
            errors.append(str(e))

    threads = [threading.Thread(target=run) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(done) == 1 and len(errors) == 1, (done, errors)
    assert "another run" in errors[0] or "earlier run" in errors[0], errors[0]


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda s, d: s.modes(count=10**20), "count"),
        (lambda s, d: rothe.study_time(s, d, halvings=2**70), "halvings"),
        (lambda s, d: rothe.study_time(s, d, halvings=1, jobs=2**70), "jobs"),
        (lambda s, d: s.run(threads=2**70), "threads"),
    ],
)
def test_counts_out_of_range_name_their_argument(tmp_path, call, name):
    with pytest.raises(rothe.Error, match=name):
        call(rothe.loads(BAR), tmp_path / "o")


def test_a_non_finite_number_in_a_dict_is_named_by_its_field():
    d = rothe.loads(BAR).to_dict()
    d["materials"]["steel"]["E"] = float("nan")
    with pytest.raises(rothe.Error, match=r"materials\.steel\.E: nan"):
        rothe.from_dict(d)
    d = rothe.loads(BAR).to_dict()
    d["bodies"][0]["mesh"]["size"] = [1.0, float("inf")]
    with pytest.raises(rothe.Error, match=r"bodies\[0\]\.mesh\.size\[1\]: inf"):
        rothe.from_dict(d)
