"""Every figure the validation report shows has units on every axis and both simulators
visibly drawn (no line flattened to a sliver of its axis)."""

from __future__ import annotations

import re

import numpy as np
import pytest

from abdsim.validation import plots, validate

UNIT = re.compile(r"\[[^\]]+\]")  # "time [s]", "gap [mm]", "Σ |L| [kg m²/s]"


@pytest.fixture(scope="module")
def figures(tmp_path_factory):
    """Validate the tossed scene past its first contact (1.29 s), keeping every figure."""
    seen = {}
    original = plots._save

    def keep(fig, path, **options):
        seen[path.name] = fig
        return original(fig, path, **options)

    mp = pytest.MonkeyPatch()
    mp.setattr(plots, "_save", keep)
    try:
        out = tmp_path_factory.mktemp("plots")
        res = validate(duration=1.4, dt=2e-3, out=out, progress=False, mcap=False)
    finally:
        mp.undo()
    return res, seen


def axis_texts(ax):
    texts = [ax.get_title()] + [line.get_label() for line in ax.get_lines()]
    legend = ax.get_legend()
    if legend is not None:
        texts += [t.get_text() for t in legend.get_texts()]
    return texts


def test_every_report_figure_has_units_and_both_simulators(figures):
    res, seen = figures
    report = res.report.read_text()
    shown = re.findall(r"!\[[^\]]*\]\(([^)]+\.png)\)", report)
    assert set(shown) == {
        "snapshots.png",
        "free_flight.png",
        "contact.png",
        "heights.png",
        "conservation.png",
    }
    for name in shown:
        fig = seen[name]
        texts = []
        for ax in fig.axes:
            labels = [ax.get_xlabel(), ax.get_ylabel()]
            if hasattr(ax, "get_zlabel"):
                labels.append(ax.get_zlabel())
            for label in labels:
                assert UNIT.search(label), f"{name}: axis label {label!r} has no [unit]"
            texts += axis_texts(ax)
        joined = " ".join(texts)
        assert "abdsim" in joined and "MuJoCo" in joined, f"{name} lacks a simulator: {texts}"


def test_lines_fill_their_axes(figures):
    _, seen = figures
    checked = 0
    for name, fig in seen.items():
        for ax in fig.axes:
            if hasattr(ax, "get_zlabel") or ax.get_yscale() != "linear":
                continue
            lo, hi = ax.get_ylim()
            x0, x1 = ax.get_xlim()
            for line in ax.get_lines():
                if line.get_label().startswith("_"):
                    continue  # unlabelled guides (zero line, phase marker)
                x, y = (np.asarray(d, dtype=float) for d in line.get_data())
                if line.get_transform() == ax.transData:  # axhline's x is in axes units
                    y = y[(x >= x0) & (x <= x1)]
                finite = np.isfinite(y)
                drawn = (
                    finite
                    if line.get_marker() not in ("None", "", None)
                    else (
                        finite & (np.roll(finite, 1) | np.roll(finite, -1))  # a segment needs two
                    )
                )
                assert drawn.any(), f"{name}: {line.get_label()!r} draws nothing in view"
                y = y[finite]
                assert lo <= y.min() and y.max() <= hi, f"{name}: {line.get_label()!r} clipped"
                if np.ptp(y) > 0:
                    ratio = np.ptp(y) / (hi - lo)
                    assert ratio > 0.02, f"{name}: {line.get_label()!r} spans {ratio:.1%}"
                checked += 1
    assert checked > 20


def test_identical_error_curves_are_one_labelled_line():
    t = np.linspace(0, 1, 50)
    same = 1e-6 * t**2
    curves = np.stack([same, same * (1 + 1e-9), 3 * same], axis=1)
    groups = plots._group_identical(curves, ["a", "b", "c"])
    assert [label for label, _ in groups] == ["a, b (identical)", "c"]
    np.testing.assert_array_equal(groups[1][1], 3 * same)
