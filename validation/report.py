"""Writes report.md (tables + plots a person reads at a glance) and metrics.json."""

from __future__ import annotations

import json
from pathlib import Path

from abdsim.validation.compare import Check
from abdsim.validation.speed import describe

METRICS_SCHEMA = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "abdsim validate metrics",
    "type": "object",
    "required": [
        "scene",
        "passed",
        "settings",
        "tolerances",
        "checks",
        "inertia",
        "free_flight",
        "contact",
        "timing",
    ],
    "properties": {
        "scene": {"type": "string"},
        "passed": {"type": "boolean"},
        "settings": {"type": "object"},
        "tolerances": {"type": "object", "additionalProperties": {"type": "number"}},
        "checks": {
            "type": "array",
            "items": {
                "type": "object",
                "required": ["name", "body", "value", "limit", "kind", "passed"],
                "properties": {
                    "name": {"type": "string"},
                    "body": {"type": "string"},
                    "value": {"type": ["number", "null"]},
                    "limit": {"type": "number"},
                    "kind": {"enum": ["max", "min"]},
                    "passed": {"type": "boolean"},
                    "detail": {"type": "string"},
                },
            },
        },
        "inertia": {"type": "array"},
        "free_flight": {"type": "object"},
        "contact": {"type": "object"},
        "timing": {"type": "object"},
        "files": {"type": "object"},
    },
}


def _fmt(x: float) -> str:
    if x is None:
        return "n/a"
    if x == float("inf"):
        return "never"
    return f"{x:.3g}" if abs(x) >= 1e-3 or x == 0 else f"{x:.2e}"


def _json_safe(obj):
    if isinstance(obj, float):
        return obj if obj == obj and abs(obj) != float("inf") else None
    if isinstance(obj, dict):
        return {k: _json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_json_safe(v) for v in obj]
    return obj


def write_metrics(path: Path, metrics: dict) -> Path:
    path.write_text(json.dumps(_json_safe(metrics), indent=2))
    return path


def write_report(path: Path, metrics: dict, checks: list[Check], plots: dict[str, str]) -> Path:
    """A Markdown report: verdict, failing checks first, then tables and plots."""
    failed = [c for c in checks if not c.passed]
    s = metrics["settings"]
    verdict = (
        f"**{'PASSED' if not failed else 'FAILED'}**: {len(checks) - len(failed)} of "
        f"{len(checks)} checks within tolerance."
    )
    if "integrator" in s:
        verdict += (
            f" abdsim ({s['integrator'].upper()}, h = {s['dt']:g} s) against MuJoCo "
            f"({s['mujoco_integrator']}, h = {s['dt']:g} s) and a Pinocchio free-flight "
            f"reference (RK4 on SE(3)), {s['duration']:g} s simulated."
        )
    lines = [f"# abdsim validation — `{Path(metrics['scene']).name}`", "", verdict, ""]
    if plots.get("snapshots"):
        lines += [
            f"![abdsim (top) and MuJoCo (bottom) at a few times]({plots['snapshots']})",
            "",
        ]
    for note in metrics.get("notes", []):
        lines += [f"> Note: {note}", ""]
    if failed:
        lines += [
            "## Failed checks",
            "",
            "| check | body | value | limit | detail |",
            "|---|---|---|---|---|",
        ]
        lines += [
            f"| {c.name} | **{c.body}** | {_fmt(c.value)} | {c.kind} {_fmt(c.limit)} | {c.detail} |"
            for c in failed
        ]
        lines.append("")
    lines += [
        "## Mass properties",
        "",
        "abdsim's `to_rigid_body` of each loaded body against the peers' models (relative errors).",
        "",
        "| body | reference | mass [kg] | mass | centre | inertia |",
        "|---|---|---|---|---|---|",
    ]
    for r in metrics["inertia"]:
        lines.append(
            f"| {r['body']} | {r['reference']} | {r['mass']:.6g} | "
            f"{_fmt(r['mass_rel_err'])} | {_fmt(r['center_rel_err'])} | "
            f"{_fmt(r['inertia_rel_err'])} |"
        )
    ff = metrics["free_flight"]
    if ff:
        lines += [
            "",
            f"## Free flight (0 – {ff['t_free']:.3f} s, before any contact)",
            "",
            "| body | pos. err. vs MuJoCo [m] | orient. err. [rad] | pos. err. vs Pinocchio [m] "
            "| MuJoCo vs Pinocchio [m] | ang. momentum drift |",
            "|---|---|---|---|---|---|",
        ]
        for name, b in ff["bodies"].items():
            lines.append(
                f"| {name} | {_fmt(b['position_error_mujoco'])} | "
                f"{_fmt(b['orientation_error_mujoco'])} | "
                f"{_fmt(b.get('position_error_pinocchio'))} | "
                f"{_fmt(b.get('mujoco_vs_pinocchio'))} | {_fmt(b['angular_momentum_drift'])} |"
            )
        lines += [
            "",
            f"Relative energy drift of abdsim over free flight: {_fmt(ff['energy_drift'])}. "
            "MuJoCo and Pinocchio integrate rigid bodies with RK4; abdsim integrates affine "
            "bodies (12 DOF, stiff shape energy) implicitly, so its error is the BDF "
            "discretisation error plus the O(1/κ) deviation of A from a rotation.",
            "",
        ]
        if plots.get("free_flight"):
            lines += [f"![free-flight errors]({plots['free_flight']})", ""]
    e = metrics.get("energy")
    if e:
        lines += [
            "## Energy",
            "",
            f"abdsim's total energy (kinetic + gravity + stored in the shape and barrier "
            f"potentials) goes from {_fmt(e['energy_start'])} J to {_fmt(e['energy_end'])} J "
            f"(largest {_fmt(e['energy_max'])} J); its largest rise between two samples is "
            f"{_fmt(e['energy_gain'])} of its magnitude (at t = {_fmt(e['energy_gain_time'])} s). "
            "Contact may remove energy (BDF1, contact damping), never add it.",
            "",
        ]
    c = metrics["contact"]
    if c:
        lines += [
            "## Contact",
            "",
            f"- first contact: abdsim {_fmt(c['first_contact_abdsim'])} s, MuJoCo "
            f"{_fmt(c['first_contact_mujoco'])} s",
            f"- abdsim minimum contact distance: {_fmt(c['abdsim_min_contact_distance'])} m "
            f"(IPC barrier: never zero or negative)",
            f"- MuJoCo maximum penetration: {_fmt(c['mujoco_max_penetration'])} m (soft "
            "contact allows overlap)",
            "",
            "| body | final height abdsim [m] | final height MuJoCo [m] | "
            "final speed abdsim [m/s] | final speed MuJoCo [m/s] | at rest in both | "
            "restitution per impact abdsim | restitution per impact MuJoCo |",
            "|---|---|---|---|---|---|---|---|",
        ]
        for name, b in c["bodies"].items():
            e_abd, e_mj = (
                ", ".join(f"{e:.2f}" for e in b.get(k, [])) or "-"
                for k in ("restitution_abdsim", "restitution_mujoco")
            )
            lines.append(
                f"| {name} | {b['rest_height_abdsim']:.5f} | {b['rest_height_mujoco']:.5f}"
                f" | {_fmt(b['final_speed_abdsim'])} | {_fmt(b['final_speed_mujoco'])} | "
                f"{'yes' if b['at_rest_in_both'] else 'no'} | {e_abd} | {e_mj} |"
            )
        lines += [
            "",
            "Contact models differ by design: abdsim keeps a positive gap (IPC barrier, "
            "activation distance d̂) and its friction is smoothed (creep below ε_v); MuJoCo's "
            "soft contacts penetrate slightly. Dissipation is matched: abdsim's contact damping "
            "ratio is the MJCF solref damping ratio (MuJoCo's default 1: critically damped); "
            "solref's time constant is not (abdsim's barrier stiffness is IPC's). Restitution "
            "per impact is e = v_up / v_down of each body's centre of mass, the same measure "
            "for both. Final heights are asserted for bodies at rest in both simulators "
            "(they may differ by up to d̂ plus MuJoCo's penetration); the others are reported "
            "and plotted.",
            "",
        ]
        if plots.get("contact"):
            lines += [f"![contact]({plots['contact']})", ""]
    if plots.get("heights") or plots.get("conservation"):
        lines += ["## Trajectories and conservation", ""]
    for key in ("heights", "conservation"):
        if plots.get(key):
            lines += [f"![{key}]({plots[key]})", ""]
    t = metrics["timing"]
    if t:
        lines += [
            "## Speed",
            "",
            f"- {describe(t['speed_vs_mujoco'], 'stepping only (time inside step())')}.",
            f"- {describe(t['speed_vs_mujoco_end_to_end'], 'end to end')} (the whole run: "
            "stepping, sampling the state and, for abdsim, writing the MCAP log).",
            "",
            "| simulator | steps | stepping [s] | stepping [steps/s] | end to end [s] | "
            "end to end [steps/s] |",
            "|---|---|---|---|---|---|",
        ]
        for sim, tt in t["simulators"].items():
            lines.append(
                f"| {sim} | {tt['steps']} | {tt['wall_time']:.3f} | {tt['steps_per_s']:.0f} | "
                f"{tt['end_to_end_wall_time']:.3f} | {tt['end_to_end_steps_per_s']:.0f} |"
            )
        lines += [
            "",
            f"Mean Newton iterations per abdsim step: {_fmt(t.get('mean_newton_iterations'))}. "
            "Pinocchio runs the free-flight phase only.",
            "",
        ]
    lines += [
        "",
        "## All checks",
        "",
        "| check | body | value | limit | pass |",
        "|---|---|---|---|---|",
    ]
    lines += [
        f"| {c.name} | {c.body} | {_fmt(c.value)} | {c.kind} {_fmt(c.limit)} | "
        f"{'✅' if c.passed else '❌'} |"
        for c in checks
    ]
    path.write_text("\n".join(lines) + "\n")
    return path
