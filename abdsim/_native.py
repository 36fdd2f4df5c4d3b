"""Loads the compiled core, making sure coal's shared library can be found.

The extension's RPATH points at ``site-packages/cmeel.prefix/lib``, where the ``libcoal``
wheel puts ``libcoal.so``. When abdsim and libcoal end up in different site-packages (a
virtual environment over system packages, ``--user`` installs), that RPATH misses; we then
pre-load libcoal from wherever it is on ``sys.path`` so the import still works.
"""

from __future__ import annotations

import ctypes
import glob
import importlib.util
import os
import sys


def _preload_coal() -> bool:
    for entry in sys.path:
        pattern = os.path.join(entry or ".", "cmeel.prefix", "lib", "libcoal.so*")
        for path in sorted(glob.glob(pattern)):
            try:
                ctypes.CDLL(path, mode=ctypes.RTLD_GLOBAL)
                return True
            except OSError:
                continue
    return False


def _missing_core_message() -> str:
    """One line saying why there is no ``abdsim._core`` here and what to do about it."""
    here = os.path.dirname(os.path.abspath(__file__))
    if not os.path.isdir(os.path.join(here, "cpp")):
        return f"abdsim's compiled core (_core) is missing from {here}: reinstall abdsim"
    installed = [
        os.path.join(entry, "abdsim")
        for entry in sys.path
        if entry and glob.glob(os.path.join(entry, "abdsim", "_core*.so"))
    ]
    where = f"the installed one is in {installed[0]}; " if installed else ""
    return (
        f"this is abdsim's source folder ({here}), which has no compiled core; {where}"
        "run Python outside the repository folder (or with `python -P`), or install abdsim "
        "for development with `pip install --no-build-isolation -e .` (see README, Developing)"
    )


try:
    from abdsim import _core
except ImportError as first_error:  # pragma: no cover - depends on the install layout
    if importlib.util.find_spec("abdsim._core") is None:
        raise ImportError(_missing_core_message()) from None
    if not _preload_coal():
        raise ImportError(
            "abdsim's compiled core could not be loaded and coal's shared library "
            "(libcoal, from the 'libcoal' wheel) was not found on sys.path: "
            f"{first_error}"
        ) from first_error
    from abdsim import _core

__all__ = ["_core"]
