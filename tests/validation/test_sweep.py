"""Sweeps: several scenes × time steps on any concurrent.futures executor."""

from concurrent.futures import ThreadPoolExecutor

from abdsim.validation import run_sweep
from abdsim.validation.scenes import default_scene
from abdsim.validation.sweep import SweepCase, default_cases, summary_table


def test_sweep_on_an_injected_executor(tmp_path):
    cases = [
        SweepCase(str(default_scene()), dt, 0.2, str(tmp_path / f"dt{dt}")) for dt in (1e-3, 2e-3)
    ]
    cases.append(SweepCase(str(tmp_path / "missing.xml"), 1e-3, 0.2, str(tmp_path / "m")))
    with ThreadPoolExecutor(max_workers=2) as pool:
        rows = run_sweep(cases, executor=pool, progress=False)
    assert [r["dt"] for r in rows] == [1e-3, 2e-3, 1e-3]  # case order kept
    assert rows[0]["passed"] and rows[1]["passed"]
    # The first step (BDF1) flies the exact parabola, so BDF2 starts without error and what
    # is left grows like h³ here: halving h divides it by ~8 (measured 8.0; an implicit Euler
    # first step left an error ½ g h² that made it ~4).
    ratio = rows[1]["max_position_error"] / rows[0]["max_position_error"]
    assert 6.0 < ratio < 10.0
    assert not rows[2]["passed"] and "FileNotFoundError" in rows[2]["error"]
    table = summary_table(rows)
    assert "tossed_bodies.xml" in table and "missing.xml" in table
    assert (tmp_path / "dt0.001" / "report.md").is_file()


def test_default_cases_cover_bundled_scenes(tmp_path):
    cases = default_cases(tmp_path, 1.0, (1e-3, 5e-3))
    scenes = {c.scene for c in cases}
    assert any(s.endswith("tossed_bodies.xml") for s in scenes)
    assert len(cases) == 2 * len(scenes)


def test_the_default_sweep_runs_every_bundled_scene_at_dt_1e_2(tmp_path):
    """Every bundled scene (free_bodies.xml included, which it used to leave out), at the
    default step 1e-3 and at 0.01."""
    from abdsim.validation.scenes import SCENE_DIR

    cases = default_cases(tmp_path, 1.0)
    bundled = {p.name for p in SCENE_DIR.glob("*.xml")}
    assert {c.scene.rsplit("/", 1)[-1] for c in cases} == bundled
    assert {c.dt for c in cases} == {1e-3, 1e-2}
