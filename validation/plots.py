"""Matplotlib figures of a validation run (PNG, headless)."""

from __future__ import annotations

import functools
import threading
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from abdsim.validation.trajectory import Trajectory, rotation_angle  # noqa: E402

# matplotlib (pyplot state, mathtext's parser) is not thread-safe; sweeps may run cases on
# threads, so every figure is drawn under one lock.
_LOCK = threading.Lock()


def _locked(fn):
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        with _LOCK:
            return fn(*args, **kwargs)

    return wrapper


def _common(a: Trajectory, b: Trajectory) -> int:
    return min(len(a.time), len(b.time))


def _body_colors(names: list[str]) -> dict[str, tuple]:
    cmap = plt.get_cmap("tab10")
    return {name: cmap(i % 10) for i, name in enumerate(names)}


@_locked
def plot_heights(abd: Trajectory, mj: Trajectory, path: Path) -> Path:
    """Centre-of-mass height of every body, one panel per simulator (own scales: abdsim's
    bodies bounce nearly elastically, MuJoCo's come to rest), same colour per body."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharex=True)
    colors = _body_colors(abd.names)
    for ax, tr in zip(axes, (abd, mj), strict=True):
        for i, name in enumerate(tr.names):
            ax.plot(tr.time, tr.com[:, i, 2], color=colors.get(name), label=name)
        ax.set_title(f"{_LABEL[tr.simulator]}: centre-of-mass heights")
        ax.set_xlabel("time [s]")
        ax.set_ylabel("centre-of-mass height [m]")
        ax.grid(alpha=0.3)
    axes[0].legend(ncol=2, fontsize=8)
    return _save(fig, path)


def _group_identical(curves: np.ndarray, names: list[str], rtol: float = 1e-6) -> list:
    """Bodies whose curves agree to ``rtol`` (e.g. the same gravity error for every body)
    drawn as one labelled line: [(label, curve)]."""
    groups: list[tuple[list[str], np.ndarray]] = []
    for i, name in enumerate(names):
        c = curves[:, i]
        for members, ref in groups:
            if np.allclose(c, ref, rtol=rtol, atol=1e-300):
                members.append(name)
                break
        else:
            groups.append(([name], c))
    out = []
    for members, c in groups:
        label = members[0] if len(members) == 1 else f"{', '.join(members)} (identical)"
        out.append((label, c))
    return out


@_locked
def plot_free_flight_errors(
    abd: Trajectory, mj: Trajectory, pin: Trajectory | None, t_free: float, path: Path
) -> Path:
    """Position and orientation error to MuJoCo (and Pinocchio) over the free-flight phase."""
    n = _common(abd, mj)
    t = abd.time[:n]
    w = t <= t_free + 1e-12
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    pos = np.linalg.norm(abd.com[:n] - mj.com[:n], axis=-1)
    rot = rotation_angle(abd.rotation[:n], mj.rotation[:n])
    for ax, err in ((ax1, pos), (ax2, rot)):
        for label, c in _group_identical(err[w], abd.names):
            ax.semilogy(t[w], np.maximum(c, 1e-16), label=f"abdsim − MuJoCo: {label}")
    if pin is not None:
        m = min(n, len(pin.time))
        pin_err = np.linalg.norm(mj.com[:m] - pin.com[:m], axis=-1).max(axis=1)
        wm = pin.time[:m] <= t_free + 1e-12
        ax1.semilogy(
            pin.time[:m][wm],
            np.maximum(pin_err[wm], 1e-16),
            "k:",
            label="MuJoCo − Pinocchio (max over bodies)",
        )
    ax1.set_title("free flight: centre-of-mass error")
    ax1.set_ylabel("|c_abdsim − c_MuJoCo| [m]")
    ax2.set_title("free flight: orientation error to MuJoCo")
    ax2.set_ylabel("rotation angle between orientations [rad]")
    for ax in (ax1, ax2):
        ax.set_xlabel("time [s]")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)
    return _save(fig, path)


@_locked
def plot_conservation(trajs: list[Trajectory], t_free: float, path: Path) -> Path:
    """Energy change and total angular momentum, one column per simulator (own scales)."""
    fig, axes = plt.subplots(2, len(trajs), figsize=(4.2 * len(trajs), 6.5), squeeze=False)
    for k, tr in enumerate(trajs):
        ax_e, ax_l = axes[0, k], axes[1, k]
        ax_e.plot(tr.time, tr.energy - tr.energy[0], color=f"C{k}", label=_LABEL[tr.simulator])
        Lmag = np.linalg.norm(tr.angular_momentum, axis=-1).sum(axis=1)
        ax_l.plot(tr.time, Lmag, color=f"C{k}", label=_LABEL[tr.simulator])
        ax_e.set_title(f"{_LABEL[tr.simulator]}: energy change")
        ax_e.set_ylabel("E(t) − E(0) [J]")
        ax_l.set_title(f"{_LABEL[tr.simulator]}: angular momentum")
        ax_l.set_ylabel("Σ |L about COM| [kg m²/s]")
        for ax in (ax_e, ax_l):
            ax.axvline(t_free, color="gray", lw=0.8, ls=":")
            ax.set_xlabel("time [s]")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=8)
    return _save(fig, path)


@_locked
def plot_contact(abd: Trajectory, mj: Trajectory, path: Path, d_hat: float | None = None) -> Path:
    """abdsim's smallest gap (always > 0) and MuJoCo's contact distance (< 0: penetration),
    each on its own axis: a 1 mm gap disappears on a 100 mm penetration scale."""
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    # Markers: abdsim reports a gap only while surfaces are within d̂, often at isolated
    # samples that a line alone would not draw.
    ax1.plot(
        abd.time, abd.contact_distance * 1e3, "o-", ms=4, color="C0", label="abdsim smallest gap"
    )
    if d_hat:
        ax1.axhline(d_hat * 1e3, color="gray", lw=0.8, ls="--", label="barrier d̂")
    gaps = abd.contact_distance[np.isfinite(abd.contact_distance)] * 1e3
    top = max(float(gaps.max(initial=0.0)), (d_hat or 0.0) * 1e3)
    ax1.set_ylim(0.0, 1.15 * top if top > 0 else 1.0)  # room above d̂ for the line to show
    ax1.set_title("abdsim: smallest distance between surfaces (never ≤ 0)")
    ax1.set_ylabel("gap [mm]")
    ax2.plot(mj.time, mj.contact_distance * 1e3, color="C1", label="MuJoCo contact distance")
    ax2.axhline(0.0, color="k", lw=0.8)
    ax2.set_title("MuJoCo: contact distance (< 0: penetration)")
    ax2.set_ylabel("distance [mm]")
    for ax in (ax1, ax2):
        ax.set_xlabel("time [s]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    return _save(fig, path)


@_locked
def plot_joints(time: np.ndarray, abd: np.ndarray, mj: np.ndarray, names: list[str], path: Path):
    """Joint coordinates (abdsim solid, MuJoCo dashed) and their difference, per joint."""
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    for k, name in enumerate(names):
        (line,) = top.plot(time, abd[:, k], label=name)
        top.plot(time, mj[:, k], "--", color=line.get_color(), alpha=0.8)
        bottom.semilogy(time, np.abs(abd[:, k] - mj[:, k]) + 1e-16, color=line.get_color())
    top.set_ylabel("joint position [rad or m]")
    top.set_title("Joints: abdsim (solid) vs MuJoCo RK4 (dashed)")
    top.legend(ncol=4, fontsize=8)
    bottom.set_xlabel("time [s]")
    bottom.set_ylabel("|abdsim - MuJoCo|")
    for ax in (top, bottom):
        ax.grid(alpha=0.3)
    return _save(fig, path)


@_locked
def plot_robot_joints(
    time: np.ndarray, series: dict[str, np.ndarray], names: list[str], ylabel: str, path: Path
) -> Path:
    """One panel per joint: each simulator's curve (abdsim solid, references dashed)."""
    n = len(names)
    cols = min(n, 3)
    rows = -(-n // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3.6 * cols, 2.4 * rows), squeeze=False)
    for k, name in enumerate(names):
        ax = axes[k // cols][k % cols]
        for style, (label, values) in zip(("-", "--", ":"), series.items(), strict=False):
            ax.plot(time, values[:, k], style, label=label)
        ax.set_title(name, fontsize=9)
        ax.grid(alpha=0.3)
        ax.tick_params(labelsize=7)
    for k in range(n, rows * cols):
        axes[k // cols][k % cols].axis("off")
    axes[0][0].legend(fontsize=7)
    fig.supxlabel("time [s]", fontsize=9)
    fig.supylabel(ylabel, fontsize=9)
    return _save(fig, path)


@_locked
def plot_base_height(time: np.ndarray, series: dict[str, np.ndarray], path: Path) -> Path:
    """A dropped robot's base height over time, one curve per simulator."""
    fig, ax = plt.subplots(figsize=(7, 3.5))
    for style, (label, values) in zip(("-", "--"), series.items(), strict=False):
        ax.plot(time, values, style, label=label)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("base height [m]")
    ax.set_title("Floating robot dropped on the ground")
    ax.grid(alpha=0.3)
    ax.legend()
    return _save(fig, path)


@_locked
def plot_snapshots(
    abd: Trajectory,
    mj: Trajectory,
    meshes: list[tuple[np.ndarray, np.ndarray]],
    centers: np.ndarray,
    path: Path,
    count: int = 4,
) -> Path:
    """The scene itself: abdsim (top row) and MuJoCo (bottom row) at ``count`` times.

    ``meshes`` are the bodies' surfaces in their body frames and ``centers`` their centres
    of mass in those frames, so each simulator's (centre of mass, orientation) places them:
    x = c + R (x̄ − c̄). Drawn with matplotlib's 3D axes, headless.
    """
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    n = _common(abd, mj)
    picks = np.unique(np.linspace(0, n - 1, count).round().astype(int))
    colors = _body_colors(abd.names)
    both = np.concatenate([abd.com[:n], mj.com[:n]], axis=1).reshape(-1, 3)
    radius = max(float(np.max([np.abs(v).max() for v, _ in meshes])), 0.05)
    lo = both.min(axis=0) - radius
    hi = both.max(axis=0) + radius
    lo[2] = min(lo[2], 0.0)
    # A square floor (x and y spans equal) keeps the bodies' proportions readable.
    half = 0.5 * float(np.max(hi[:2] - lo[:2]))
    mid = 0.5 * (lo[:2] + hi[:2])
    lo[:2], hi[:2] = mid - half, mid + half
    fig = plt.figure(figsize=(3.2 * len(picks), 7.0))
    for row, tr in enumerate((abd, mj)):
        for col, k in enumerate(picks):
            ax = fig.add_subplot(2, len(picks), row * len(picks) + col + 1, projection="3d")
            for i, (name, (v, f)) in enumerate(zip(tr.names, meshes, strict=True)):
                x = tr.com[k, i] + (np.asarray(v) - centers[i]) @ tr.rotation[k, i].T
                ax.add_collection3d(
                    Poly3DCollection(x[np.asarray(f)], facecolor=colors[name], edgecolor="none")
                )
            ground = np.array([[lo[0], lo[1], 0], [hi[0], lo[1], 0], [hi[0], hi[1], 0]])
            ground = np.vstack([ground, [lo[0], hi[1], 0]])
            ax.add_collection3d(Poly3DCollection([ground], facecolor=(0.8, 0.8, 0.8, 0.4)))
            ax.set(xlim=(lo[0], hi[0]), ylim=(lo[1], hi[1]), zlim=(lo[2], hi[2]))
            ax.set_box_aspect(hi - lo)
            ax.set_xlabel("x [m]", fontsize=7)
            ax.set_ylabel("y [m]", fontsize=7)
            ax.set_zlabel("z [m]", fontsize=7)
            ax.tick_params(labelsize=6)
            ax.locator_params(nbins=4)
            ax.view_init(elev=15, azim=-65)
            ax.set_title(f"{_LABEL[tr.simulator]}, t = {tr.time[k]:.2f} s", fontsize=9)
    # tight_layout on 3D axes costs seconds; fixed margins do as well here.
    fig.subplots_adjust(left=0.0, right=0.97, bottom=0.05, top=0.95, wspace=0.05, hspace=0.25)
    return _save(fig, path, tight=False)


_LABEL = {"abdsim": "abdsim", "mujoco": "MuJoCo", "pinocchio": "Pinocchio"}


def _save(fig: plt.Figure, path: Path, tight: bool = True) -> Path:
    if tight:
        fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
