"""MJCF elements the loader reads but abdsim does not simulate yet, named in the notes.

Tendons and equality constraints have no abdsim counterpart (nor actuators when jointed
bodies are loaded kinematic): rather than being dropped without a word, each kind is listed
by name in ``LoadResult.notes`` (and so warned once by the loader).
"""

from __future__ import annotations


def _names(model, kind: str, count: int) -> list[str]:
    getter = getattr(model, kind)
    return [getter(i).name or f"{kind}{i}" for i in range(count)]


def unsimulated_notes(mujoco, model, articulated: bool = False) -> list[str]:
    """One note per kind of element that is present but not simulated (articulated: the
    actuators get their own notes, ``bridges/_mjcf_actuators.py``)."""
    notes = []
    if model.ntendon:
        names = _names(model, "tendon", model.ntendon)
        notes.append(f"{model.ntendon} tendon(s) not simulated: {names}")
    if model.neq:
        kinds = [mujoco.mjtEq(int(t)).name[len("mjEQ_") :].lower() for t in model.eq_type]
        names = [f"{n} ({k})" for n, k in zip(_names(model, "eq", model.neq), kinds, strict=True)]
        notes.append(f"{model.neq} equality constraint(s) not simulated: {names}")
    if model.nu and not articulated:
        names = _names(model, "actuator", model.nu)
        notes.append(
            f"{model.nu} actuator(s) not simulated (jointed bodies are kinematic): {names}"
        )
    return notes
