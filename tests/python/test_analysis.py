# Analyses: splat.popping's numbers equal the CLI's summary.json; its report is the CLI's;
# splat.study and splat.iso_surface.
import json

import numpy as np
import pytest

import splat

SPEC = "synthetic:phantom:24"
SWEEP = dict(size=(32, 32), from_=40, to=46, step=1, refine=3)
FLAGS = ["--size", "32x32", "--from", "40", "--to", "46", "--step", "1", "--refine", "3"]


@pytest.fixture(scope="module")
def pop(phantom):
    return splat.popping(phantom, **SWEEP)


@pytest.fixture(scope="module")
def summary(cli, tmp_path_factory):
    out = tmp_path_factory.mktemp("pop")
    cli("popping", SPEC, *FLAGS, "--report", out, "-q")
    return json.loads((out / "summary.json").read_text())


def test_popping_numbers_equal_the_clis_summary(pop, summary):
    assert list(pop.angles) == [40, 41, 42, 43, 44, 45, 46]
    assert pop.renderers == ["axis", "sheet", "reference"] == list(summary["renderers"])
    for name, s in pop.series.items():
        ref = summary["renderers"][name]
        for key in ["spike_ratio", "median_T", "flicker_ratio", "threshold"]:
            assert s[key] == pytest.approx(ref[key], rel=1e-12, abs=0), (name, key)
        assert np.median(s["e"]) == pytest.approx(ref["median_error"], rel=1e-12, abs=0)
        events = [e for e in pop.events if e["renderer"] == name]
        assert len(events) == len(ref["events"])
        for e, r in zip(events, ref["events"]):
            for key in ["angle_from", "angle_to", "refined_jump", "refined_width",
                        "refined_slope", "refined_angle", "sheet_axis_before",
                        "sheet_axis_after", "predicted"]:
                assert e[key] == pytest.approx(r[key], rel=1e-12, abs=0), (name, key)
            assert e["signal"] == pytest.approx(r["J"], rel=1e-12, abs=0)
    assert list(pop.predicted_switches) == pytest.approx(summary["predicted_switches"], rel=1e-12)
    axis = pop.series["axis"]
    assert axis["T"].shape == (6,) and axis["e"].shape == (7,) and axis["T"].dtype == np.float64


def test_popping_write_report_is_the_clis(pop, summary, tmp):
    pop.write_report(str(tmp))
    assert sorted(p.name for p in tmp.iterdir()) == ["metrics.csv", "report.html", "summary.json"]
    mine = json.loads((tmp / "summary.json").read_text())
    for j in (mine, summary):
        j.pop("timings")
        for r in j["renderers"].values():
            r.pop("ms_per_frame")
            r.pop("total_ms")
    assert mine == summary
    (tmp / "file").write_text("")
    with pytest.raises(splat.Error):  # a folder under a file
        pop.write_report(str(tmp / "file" / "folder"))


def test_popping_refuses_a_bad_sweep_like_the_cli(cli, tmp, phantom):
    p = cli("popping", SPEC, "--step", "-1", "--report", tmp, check=False)
    with pytest.raises(splat.InputError) as e:
        splat.popping(phantom, step=-1)
    assert str(e.value) == p.stderr.strip().splitlines()[-1][len("splat: error: "):]


def test_study_points_and_pareto(phantom, tmp):
    r = splat.study(phantom, sweep={"renderer": ["axis", "sheet"], "slab": [0.5, 1]},
                    size=(24, 24), repeats=1, warmup=0)
    # slab does not apply to the axis-aligned splatter: one point
    assert [p["label"] for p in r.points] == [
        "renderer=axis", "renderer=sheet slab=0.5", "renderer=sheet slab=1"]
    assert all(p["rmse"] > 0 and p["splats"] > 0 for p in r.points)
    assert any(p["pareto"] for p in r.points)
    r.write_report(str(tmp))
    assert (tmp / "study.json").exists() and (tmp / "pareto.svg").exists()


def test_iso_surface_of_the_sphere():
    v = splat.synthetic("sphere", 32)
    mesh = splat.iso_surface(v, 0.5)
    radius = np.linalg.norm(mesh.vertices - np.array(v.center), axis=1)
    assert mesh.triangles.shape[1] == 3 and mesh.triangles.max() < len(mesh.vertices)
    assert np.abs(radius - 0.375 * 32).max() < 0.5


def test_popping_over_a_camera_path_equals_the_cli(cli, tmp, phantom):
    path = tmp / "path.json"
    path.write_text(json.dumps({"keys": [{"azimuth": 40, "elevation": 5}, {"azimuth": 46}]}))
    pop = splat.popping(phantom, path=str(path), frames=5, size=(24, 24), refine=2)
    cli("popping", SPEC, "--path", path, "--frames", 5, "--size", "24x24", "--refine", 2,
        "--report", tmp / "cli", "-q")
    summary = json.loads((tmp / "cli" / "summary.json").read_text())
    assert len(pop.angles) == 5
    for name, s in pop.series.items():
        for key in ["spike_ratio", "median_T", "threshold"]:
            assert s[key] == pytest.approx(summary["renderers"][name][key], rel=1e-12, abs=0)
    p = cli("popping", SPEC, "--path", path, "--step", 2, "--report", tmp / "x", check=False)
    with pytest.raises(splat.InputError) as e:
        splat.popping(phantom, path=str(path), step=2)
    assert str(e.value) == p.stderr.strip().splitlines()[-1][len("splat: error: "):]
