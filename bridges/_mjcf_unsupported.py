"""MJCF elements the loader reads but abdsim does not simulate yet, named in the notes.

Tendons (but a fixed tendon that only transmits an actuator's force to one joint) and equality
constraints have no abdsim counterpart (nor actuators when jointed bodies are loaded
kinematic): rather than being dropped without a word, each kind is listed by name in
``LoadResult.notes`` (and so warned once by the loader).
"""

from __future__ import annotations

from abdsim.bridges._mjcf_tendons import transmission_only


def _names(model, kind: str, count: int) -> list[str]:
    getter = getattr(model, kind)
    return [getter(i).name or f"{kind}{i}" for i in range(count)]


def unsimulated_notes(mujoco, model, articulated: bool = False) -> list[str]:
    """One note per kind of element that is present but not simulated (articulated: the
    actuators get their own notes, ``bridges/_mjcf_actuators.py``)."""
    notes = []
    # A fixed tendon on one joint without physics of its own is only an actuator's
    # transmission, which articulated loads model exactly (bridges/_mjcf_tendons.py).
    tendons = [
        name
        for t, name in enumerate(_names(model, "tendon", model.ntendon))
        if not (articulated and transmission_only(mujoco, model, t))
    ]
    if tendons:
        notes.append(f"{len(tendons)} tendon(s) not simulated: {tendons}")
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
