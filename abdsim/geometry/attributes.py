"""Named, typed per-element attributes: the ``meta``, ``instances`` and ``vertices`` collections.

A collection behaves like a dict of numpy arrays whose leading dimension is the number of
elements (1 for ``meta``). Every attribute remembers its dtype, its per-element shape and its
default, so ``resize`` can grow a collection with correct defaults. ``meta`` values read back
without the leading dimension (a scalar reads as a numpy scalar), the others as views that
can be edited in place.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass(frozen=True)
class _Spec:
    dtype: np.dtype
    shape: tuple[int, ...]
    default: np.ndarray


class AttributeCollection:
    """A dict-like set of attributes over ``size`` elements.

    Args:
        name: ``"meta"``, ``"instances"`` or ``"vertices"``, used in error messages.
        size: number of elements.
        squeeze: read values without the leading element dimension (used by ``meta``).
    """

    def __init__(self, name: str, size: int, squeeze: bool = False) -> None:
        self._name = name
        self._size = int(size)
        self._squeeze = squeeze
        self._data: dict[str, np.ndarray] = {}
        self._specs: dict[str, _Spec] = {}

    # -- dict protocol ------------------------------------------------------------------
    def __contains__(self, key: object) -> bool:
        return key in self._data

    def __iter__(self) -> Iterator[str]:
        return iter(self._data)

    def __len__(self) -> int:
        return len(self._data)

    def keys(self) -> list[str]:
        return list(self._data)

    def items(self) -> list[tuple[str, Any]]:
        return [(k, self[k]) for k in self._data]

    def __getitem__(self, key: str) -> Any:
        if key not in self._data:
            raise KeyError(
                f"{self._name} has no attribute {key!r}; available: {sorted(self._data)}"
            )
        value = self._data[key]
        return value[0] if self._squeeze else value

    def __setitem__(self, key: str, value: Any) -> None:
        if key not in self._specs:
            arr = np.asarray(value)
            per_element = arr.shape if self._squeeze else arr.shape[1:]
            self.create(key, np.zeros(per_element, dtype=arr.dtype))
        spec = self._specs[key]
        arr = np.asarray(value, dtype=spec.dtype)
        full = (self._size, *spec.shape)
        if arr.shape == spec.shape:
            arr = np.broadcast_to(arr, full)
        if arr.shape != full:
            raise ValueError(
                f"{self._name}[{key!r}] expects shape {full} (or {spec.shape} to broadcast), "
                f"got {np.asarray(value).shape}"
            )
        self._data[key] = np.array(arr, dtype=spec.dtype, copy=True)

    def __repr__(self) -> str:
        body = ", ".join(f"{k}: {v.dtype}{list(v.shape[1:])}" for k, v in self._data.items())
        return f"<{self._name} size={self._size} {{{body}}}>"

    # -- creation and sizing ------------------------------------------------------------
    @property
    def size(self) -> int:
        """Number of elements in the collection."""
        return self._size

    def create(self, key: str, default: Any, dtype: Any = None) -> None:
        """Create (or reset) an attribute filled with ``default`` for every element."""
        d = np.asarray(default, dtype=dtype)
        self._specs[key] = _Spec(d.dtype, d.shape, d.copy())
        self._data[key] = np.array(np.broadcast_to(d, (self._size, *d.shape)), copy=True)

    def dtype(self, key: str) -> np.dtype:
        return self._specs[key].dtype

    def resize(self, n: int) -> None:
        """Set the number of elements; new elements take each attribute's default."""
        n = int(n)
        if n < 0:
            raise ValueError(f"{self._name}.resize: count must be >= 0, got {n}")
        if self._squeeze and n != 1:
            raise ValueError("meta always has exactly one element")
        for key, spec in self._specs.items():
            old = self._data[key]
            new = np.array(np.broadcast_to(spec.default, (n, *spec.shape)), copy=True)
            keep = min(n, old.shape[0])
            new[:keep] = old[:keep]
            self._data[key] = new
        self._size = n
