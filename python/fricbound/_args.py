"""Checks of the arguments of the public functions: every error names the argument and what
it got, before anything reaches the library."""

from __future__ import annotations

from typing import Any

import numpy as np

#: What a complex matrix or value is refused with.
_REAL_ONLY = "fricbound needs real stiffness, mass and damping matrices"


def type_name(value: Any) -> str:
    """The type of ``value`` as an error message writes it."""
    return type(value).__name__


def real_matrix(where: str, name: str, a: Any) -> Any:
    """Refuses a complex matrix (numpy array, nested lists or scipy.sparse) or one that is not
    numeric, naming ``name``; returns ``a`` (as an array when it was not one, sparse matrices
    unchanged)."""
    if hasattr(a, "toarray") and hasattr(a, "dtype"):  # scipy.sparse
        dtype = a.dtype
    else:
        try:
            a = np.asarray(a)
        except (TypeError, ValueError) as e:
            raise TypeError(f"{where}: {name}: not a matrix of numbers ({e})") from None
        dtype = a.dtype
    if dtype.kind == "c":
        raise TypeError(f"{where}: {name}: complex matrix given (dtype {dtype}); {_REAL_ONLY}")
    if dtype.kind not in "biuf":
        raise TypeError(f"{where}: {name}: expected a matrix of real numbers, got dtype {dtype}")
    return a
