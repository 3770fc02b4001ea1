"""Checks of the arguments of the public functions: every error names the argument (or the
field path inside it, e.g. ``contacts[0].mu``) and what it got, before anything reaches the
library."""

from __future__ import annotations

import math
import numbers
import os
from typing import Any, Callable, List, Mapping, Optional

import numpy as np

#: What a complex matrix or value is refused with.
_REAL_ONLY = "fricbound needs real stiffness, mass and damping matrices"


def type_name(value: Any) -> str:
    """The type of ``value`` as an error message writes it."""
    return type(value).__name__


def integer(where: str, name: str, value: Any, minimum: int) -> int:
    """``value`` as an int ``>= minimum``; bools, floats with a fraction and non-numbers are
    refused (``TypeError``), smaller values too (``ValueError``)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Integral, float, np.floating)):
        raise TypeError(f"{where}: {name}: must be an integer, got {type_name(value)}")
    if isinstance(value, (float, np.floating)):
        if not (math.isfinite(value) and float(value).is_integer()):
            raise TypeError(f"{where}: {name}: must be an integer, got {value!r}")
    v = int(value)
    if v < minimum:
        raise ValueError(f"{where}: {name}: must be >= {minimum}, got {v}")
    return v


def optional_integer(where: str, name: str, value: Any, minimum: int) -> Optional[int]:
    """:func:`integer`, or None."""
    return None if value is None else integer(where, name, value, minimum)


def number(where: str, name: str, value: Any) -> float:
    """``value`` as a finite float (``TypeError`` for a non-number or a complex, ``ValueError``
    for NaN or infinity)."""
    if isinstance(value, (complex, np.complexfloating)):
        raise TypeError(f"{where}: {name}: complex value given; fricbound needs real numbers")
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Real, np.number)):
        raise TypeError(f"{where}: {name}: must be a number, got {type_name(value)}")
    v = float(value)
    if not math.isfinite(v):
        raise ValueError(f"{where}: {name}: must be a finite number, got {v}")
    return v


def numbers_list(where: str, name: str, values: Any) -> List[float]:
    """A sequence (or 1-D array) of finite numbers, each checked by :func:`number` and named
    ``name[i]``."""
    if isinstance(values, (str, bytes, Mapping)) or not hasattr(values, "__iter__"):
        raise TypeError(f"{where}: {name}: expected a sequence of numbers, got {type_name(values)}")
    if isinstance(values, np.ndarray) and values.ndim != 1:
        raise ValueError(f"{where}: {name}: expected a 1-D sequence, got shape {values.shape}")
    return [number(where, f"{name}[{i}]", v) for i, v in enumerate(values)]


def indices(where: str, name: str, values: Any) -> List[int]:
    """A sequence of non-negative integers (DOF indices), each named ``name[i]``."""
    if isinstance(values, (str, bytes, Mapping)) or not hasattr(values, "__iter__"):
        raise TypeError(f"{where}: {name}: expected a sequence of DOF indices, got {type_name(values)}")
    return [integer(where, f"{name}[{i}]", v, 0) for i, v in enumerate(values)]


def text(where: str, name: str, value: Any) -> str:
    """``value`` if it is a str."""
    if not isinstance(value, str):
        raise TypeError(f"{where}: {name}: expected a str, got {type_name(value)}")
    return value


def callback(where: str, name: str, value: Any) -> Optional[Callable[[dict], Any]]:
    """A callable or None."""
    if value is not None and not callable(value):
        raise TypeError(f"{where}: {name}: expected a callable or None, got {type_name(value)}")
    return value


def path_or_text(where: str, name: str, value: Any) -> None:
    """Refuses what is neither a str nor a path."""
    if not isinstance(value, (str, os.PathLike)):
        raise TypeError(
            f"{where}: {name}: expected a Scene, a path or TOML text, got {type_name(value)}"
        )


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


def scene_values(where: str, path: str, value: Any) -> None:
    """Walks the values given for scene tables (contact and load dicts, the ``analysis``,
    ``effects``, ... dicts): a NaN or infinite number, a complex value or a value that cannot
    be written into a scene raises, naming its path (``contacts[0].mu``)."""
    if isinstance(value, Mapping):
        for k, v in value.items():
            if not isinstance(k, str):
                raise TypeError(f"{where}: {path}: field names must be str, got {type_name(k)}")
            scene_values(where, f"{path}.{k}", v)
    elif isinstance(value, (list, tuple, np.ndarray)):
        for i, v in enumerate(value):
            scene_values(where, f"{path}[{i}]", v)
    elif isinstance(value, (complex, np.complexfloating)):
        raise TypeError(f"{where}: {path}: complex value given ({value}); fricbound needs real numbers")
    elif isinstance(value, (bool, np.bool_, str)) or value is None:
        return
    elif isinstance(value, (numbers.Real, np.number)):
        if not math.isfinite(float(value)):
            raise ValueError(f"{where}: {path}: must be a finite number, got {float(value)}")
    else:
        raise TypeError(f"{where}: {path}: cannot write a {type_name(value)} into a scene")


def table_list(where: str, name: str, value: Any) -> List[Mapping[str, Any]]:
    """A sequence of dicts (contacts, loads), each checked by :func:`scene_values`."""
    if isinstance(value, (str, bytes, Mapping)) or not hasattr(value, "__iter__"):
        raise TypeError(f"{where}: {name}: expected a list of dicts, got {type_name(value)}")
    out = []
    for i, item in enumerate(value):
        if not isinstance(item, Mapping):
            raise TypeError(f"{where}: {name}[{i}]: expected a dict, got {type_name(item)}")
        scene_values(where, f"{name}[{i}]", item)
        out.append(item)
    return out
