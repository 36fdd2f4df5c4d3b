"""``abdsim validate --sweep``: several scenes × time steps, run in parallel processes.

Cases are plain, picklable ``SweepCase`` records and the work function is a module-level
function, so any ``concurrent.futures.Executor`` runs them: the default process pool here,
or a Dask cluster's (``dask.distributed.Client(ADDRESS).get_executor()``, which is what
``abdsim validate --sweep --scheduler ADDRESS`` uses; tested against a ``LocalCluster`` of
processes), without changing the scene code. Each case writes its report under its own
``out`` folder, which must be reachable from the workers (a shared file system on a real
cluster).
"""

from __future__ import annotations

from concurrent.futures import Executor, ProcessPoolExecutor, as_completed
from dataclasses import asdict, dataclass
from pathlib import Path


@dataclass(frozen=True)
class SweepCase:
    scene: str
    dt: float
    duration: float
    out: str
    integrator: str = "bdf2"
    tolerances: str | None = None


def run_case(case: SweepCase) -> dict:
    """Runs one case (in a worker); returns a small summary dict (never raises)."""
    from abdsim.validation.harness import validate

    try:
        res = validate(
            case.scene,
            duration=case.duration,
            dt=case.dt,
            out=case.out,
            tolerances=case.tolerances,
            integrator=case.integrator,
            progress=False,
        )
        worst = max(res.checks, key=lambda c: 0 if c.passed else 1)
        ff = res.metrics["free_flight"].get("bodies", {})
        return {
            **asdict(case),
            "passed": res.passed,
            "checks": len(res.checks),
            "failed": len(res.failed),
            "max_position_error": max(
                (b["position_error_mujoco"] for b in ff.values()), default=float("nan")
            ),
            "speed_vs_mujoco": res.metrics["timing"]["speed_vs_mujoco"],
            "first_failure": None if res.passed else f"{worst.name} ({worst.body})",
            "error": None,
        }
    except Exception as err:  # a broken case is a row in the table, not a crashed sweep
        return {**asdict(case), "passed": False, "error": f"{type(err).__name__}: {err}"}


def default_cases(
    out: str | Path,
    duration: float,
    dts: tuple[float, ...] = (1e-3, 1e-2),
    scenes: list[str] | None = None,
) -> list[SweepCase]:
    from abdsim.validation.scenes import bundled_scenes

    scenes = scenes or [str(p) for p in bundled_scenes()]
    return [
        SweepCase(scene, dt, duration, str(Path(out) / f"{Path(scene).stem}_dt{dt:g}"))
        for scene in scenes
        for dt in dts
    ]


def run_sweep(
    cases: list[SweepCase],
    executor: Executor | None = None,
    max_workers: int | None = None,
    progress: bool = True,
) -> list[dict]:
    """Runs every case on ``executor`` (default: a local process pool); rows in case order."""
    from tqdm.auto import tqdm

    own = executor is None
    executor = executor or ProcessPoolExecutor(max_workers=max_workers)
    try:
        futures = {executor.submit(run_case, c): i for i, c in enumerate(cases)}
        rows: list[dict | None] = [None] * len(cases)
        for fut in tqdm(
            as_completed(futures), total=len(cases), desc="sweep", disable=not progress
        ):
            rows[futures[fut]] = fut.result()
        return rows  # type: ignore[return-value]
    finally:
        if own:
            executor.shutdown()


def summary_table(rows: list[dict]) -> str:
    """Markdown table of a sweep."""
    lines = [
        "| scene | dt | passed | failed checks | max pos. err. [m] "
        "| speed (× MuJoCo's, > 1 faster) | note |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        note = r.get("error") or r.get("first_failure") or ""
        lines.append(
            f"| {Path(r['scene']).name} | {r['dt']:g} | {'yes' if r['passed'] else 'NO'} "
            f"| {r.get('failed', '-')} | {r.get('max_position_error', float('nan')):.2e} | "
            f"{r.get('speed_vs_mujoco', float('nan')):.2f} | {note} |"
        )
    return "\n".join(lines)
