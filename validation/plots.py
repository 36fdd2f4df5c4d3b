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


@_locked
def plot_heights(abd: Trajectory, mj: Trajectory, path: Path) -> Path:
    """Centre-of-mass height of every body: abdsim solid, MuJoCo dashed."""
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for i, name in enumerate(abd.names):
        (line,) = ax.plot(abd.time, abd.com[:, i, 2], label=f"{name}")
        ax.plot(mj.time, mj.com[:, i, 2], "--", color=line.get_color(), alpha=0.8)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("centre-of-mass height [m]")
    ax.set_title("Trajectories: abdsim (solid) vs MuJoCo (dashed)")
    ax.legend(ncol=4, fontsize=8)
    ax.grid(alpha=0.3)
    return _save(fig, path)


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
    for i, name in enumerate(abd.names):
        ax1.semilogy(t[w], np.maximum(pos[w, i], 1e-16), label=name)
        ax2.semilogy(t[w], np.maximum(rot[w, i], 1e-16), label=name)
    if pin is not None:
        m = min(n, len(pin.time))
        pin_err = np.linalg.norm(mj.com[:m] - pin.com[:m], axis=-1).max(axis=1)
        wm = pin.time[:m] <= t_free + 1e-12
        ax1.semilogy(
            pin.time[:m][wm],
            np.maximum(pin_err[wm], 1e-16),
            "k:",
            label="MuJoCo vs Pinocchio (max)",
        )
    ax1.set_title("free flight: |c_abdsim − c_MuJoCo| [m]")
    ax2.set_title("free flight: orientation error to MuJoCo [rad]")
    for ax in (ax1, ax2):
        ax.set_xlabel("time [s]")
        ax.grid(alpha=0.3, which="both")
    ax1.legend(fontsize=7)
    return _save(fig, path)


@_locked
def plot_conservation(trajs: list[Trajectory], t_free: float, path: Path) -> Path:
    """Energy and total angular momentum magnitude of each simulator."""
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    for tr in trajs:
        ax1.plot(tr.time, tr.energy - tr.energy[0], label=tr.simulator)
        Lmag = np.linalg.norm(tr.angular_momentum, axis=-1).sum(axis=1)
        ax2.plot(tr.time, Lmag, label=tr.simulator)
    for ax in (ax1, ax2):
        ax.axvline(t_free, color="gray", lw=0.8, ls=":")
        ax.set_xlabel("time [s]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    ax1.set_title("energy change E(t) − E(0) [J]")
    ax2.set_title("Σ |angular momentum about COM| [kg m²/s]")
    return _save(fig, path)


@_locked
def plot_contact(abd: Trajectory, mj: Trajectory, path: Path) -> Path:
    """abdsim's minimum contact gap vs MuJoCo's deepest penetration."""
    fig, ax = plt.subplots(figsize=(8, 4))
    ax.plot(abd.time, abd.contact_distance * 1e3, label="abdsim min. distance")
    ax.plot(mj.time, mj.contact_distance * 1e3, label="MuJoCo contact distance (<0: penetration)")
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("[mm]")
    ax.set_title("Contact: gap (abdsim) vs penetration (MuJoCo)")
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


def _save(fig: plt.Figure, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
