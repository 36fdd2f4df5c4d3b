"""MJCF elements the loader reads but abdsim does not simulate yet, named in the notes.

Tendons, equality constraints and actuators have no abdsim counterpart until joints land
(issue 10/11): rather than being dropped without a word, each kind is listed by name in
``LoadResult.notes`` (and so warned once by the loader).
"""

from __future__ import annotations


def _names(model, kind: str, count: int) -> list[str]:
    getter = getattr(model, kind)
    return [getter(i).name or f"{kind}{i}" for i in range(count)]


def unsimulated_notes(mujoco, model) -> list[str]:
    """One note per kind of element that is present but not simulated."""
    notes = []
    if model.ntendon:
        names = _names(model, "tendon", model.ntendon)
        notes.append(f"{model.ntendon} tendon(s) not simulated: {names}")
    if model.neq:
        kinds = [mujoco.mjtEq(int(t)).name[len("mjEQ_") :].lower() for t in model.eq_type]
        names = [f"{n} ({k})" for n, k in zip(_names(model, "eq", model.neq), kinds, strict=True)]
        notes.append(f"{model.neq} equality constraint(s) not simulated: {names}")
    if model.nu:
        names = _names(model, "actuator", model.nu)
        notes.append(
            f"{model.nu} actuator(s) not simulated (jointed bodies are kinematic): {names}"
        )
    return notes
