"""The :class:`Scene`: a fricbound scene (the TOML file of the CLI) with ``--set`` overrides."""

from __future__ import annotations

import json
import math
import os
from typing import Any, Iterable, Mapping, Optional, Sequence

import numpy as np

from . import _args, _native

#: Largest model ``Scene.from_matrices`` accepts as scipy.sparse matrices (they are written
#: inline, dense, into the scene); reduce larger models first (:func:`fricbound.reduce`).
MAX_INLINE_DOFS = 500


def _toml_literal(value: Any) -> str:
    """``value`` as the right-hand side of a ``--set FIELD=VALUE`` (a TOML literal).

    ``None`` gives an empty value, which removes the field, as ``--set FIELD=`` does.
    """
    if value is None:
        return ""
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (complex, np.complexfloating)):
        raise TypeError(f"complex value given ({value}); fricbound needs real numbers")
    if isinstance(value, (float, np.floating)):
        v = float(value)
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, Mapping):
        return "{" + ", ".join(f"{json.dumps(str(k))} = {_toml_literal(v)}" for k, v in value.items()) + "}"
    if isinstance(value, (list, tuple, np.ndarray)):
        return "[" + ", ".join(_toml_literal(v) for v in value) + "]"
    raise TypeError(f"cannot write a {type(value).__name__} as a scene value")


class Scene:
    """A fricbound scene: the structure, contacts, loads, harmonics and analysis range.

    Holds the scene's TOML text, its label (the file it came from: errors name it, and
    relative mesh or Matrix Market paths are resolved from its folder) and the ``--set``
    overrides applied to it, in order. Every change is checked by the library's scene parser
    at once; ``check()`` validates the whole scene as ``fricbound check`` does.

    Create one with :meth:`from_toml`, :meth:`from_matrices` or :meth:`paper`. Scenes pickle
    (text, label, overrides), so they can be sent to Dask workers.
    """

    def __init__(self, text: str, label: str = "<string>", overrides: Iterable[str] = ()):
        self._text = str(text)
        self._label = str(label)
        self._overrides = [str(o) for o in overrides]
        _native.parse_scene(self._text, self._label, self._overrides)

    # ---- construction -------------------------------------------------------------------

    @classmethod
    def from_toml(cls, path_or_text: "str | os.PathLike[str]") -> "Scene":
        """A scene from a TOML file (path) or TOML text.

        A string with a newline or an ``=`` is taken as text, anything else as a path.
        Raises ``ValueError`` naming the line and field of a parse error, ``OSError`` when the
        file cannot be read.
        """
        _args.path_or_text("Scene.from_toml", "path_or_text", path_or_text)
        if isinstance(path_or_text, os.PathLike) or (
            "\n" not in path_or_text and "=" not in path_or_text
        ):
            path = os.path.abspath(os.fspath(path_or_text))
            with open(path, encoding="utf-8") as f:
                return cls(f.read(), path)
        return cls(path_or_text, "<string>")

    @classmethod
    def paper(cls) -> "Scene":
        """The built-in paper scene (Table 1 of Ferhatoglu & Zucca 2021, β = 120°, F0 = 120 N,
        50-350 Hz): what ``fricbound run`` solves without a scene file."""
        text, label = _native.paper_scene()
        return cls(text, label)

    @classmethod
    def from_matrices(
        cls,
        M: Any,
        C: Any,
        K: Any,
        *,
        dofs: Sequence[str],
        contacts: Sequence[Mapping[str, Any]] = (),
        loads: Sequence[Mapping[str, Any]] = (),
        freq_range_hz: "tuple[float, float]",
        outputs: Optional[Sequence[str]] = None,
        harmonics: int = 1,
        samples: int = 256,
        title: str = "",
        analysis: Optional[Mapping[str, Any]] = None,
        effects: Optional[Mapping[str, Any]] = None,
        limits: Optional[Mapping[str, Any]] = None,
        accuracy: Optional[Mapping[str, Any]] = None,
    ) -> "Scene":
        """A scene from mass, damping and stiffness matrices (the inline ``[model]`` of a
        scene file).

        Parameters
        ----------
        M, C, K : array_like or scipy.sparse matrix, (n, n)
            Mass (kg), viscous damping (N·s/m; ``None`` for none) and stiffness (N/m)
            matrices, symmetric. scipy.sparse matrices are accepted up to
            ``MAX_INLINE_DOFS`` DOFs (they are written dense into the scene); reduce larger FE
            models first with :func:`fricbound.reduce`.
        dofs : list of str
            DOF names, in matrix order.
        contacts : list of dict
            One dict per contact point with the fields of a scene's ``[[contacts]]`` (``name``,
            ``damper``, ``body``, ``angle_deg`` or ``tangent``/``normal``, ``kt`` and ``kn`` in
            N/m, ``mu``, optional ``side``, ``gap`` in m, ``initial_state``).
        loads : list of dict
            Static loads ``{"dof": ..., "value": N}`` and harmonic loads ``{"dof": ...,
            "harmonic": 1, "cos": N, "sin": N}`` (a dict with ``value`` is static).
        freq_range_hz : (float, float)
            Start and end frequency of the continuation (Hz).
        outputs : list of str, optional
            Response DOFs (default: every DOF).
        harmonics : int
            Highest harmonic H (``[harmonics] max``).
        samples : int
            AFT time samples per period (``[harmonics] samples``).
        analysis, effects, limits, accuracy : dict, optional
            Further fields of the ``[analysis]``, ``[effects]``, ``[limits]`` and
            ``[accuracy]`` tables (docs/scene.md).

        Raises ``ValueError`` naming the field (``model.mass``, ``contacts[0].mu``, ...) of a
        bad value, as a scene file's errors do, once :meth:`check` or a solve validates it;
        the schema (field names and types) is checked here, and a NaN or infinite number in
        any argument (``contacts[0].mu: must be a finite number, got nan``). A complex
        matrix (numpy complex dtype, dense or sparse) raises ``TypeError`` naming ``M``, ``C``
        or ``K``: the matrices must be real.
        """
        where = "from_matrices"
        if isinstance(dofs, (str, bytes)) or not hasattr(dofs, "__iter__"):
            raise TypeError(f"{where}: dofs: expected a list of DOF names, got {_args.type_name(dofs)}")
        dofs = [_args.text(where, f"dofs[{i}]", d) for i, d in enumerate(dofs)]
        n = len(dofs)
        arguments = {"mass": "M", "stiffness": "K", "damping": "C"}

        def matrix(name: str, a: Any) -> list:
            arg = arguments[name]
            a = _args.real_matrix(where, arg, a)
            if hasattr(a, "toarray"):  # scipy.sparse
                if a.shape[0] > MAX_INLINE_DOFS:
                    raise ValueError(
                        f"from_matrices: {arg}: model.{name}: a sparse matrix of {a.shape[0]} DOFs is too "
                        f"large to write inline (at most {MAX_INLINE_DOFS}): reduce it first with "
                        "fricbound.reduce, or export it as Matrix Market files for a scene's "
                        "[model.matrix_market]"
                    )
                a = a.toarray()
            arr = np.asarray(a, dtype=float)
            if arr.ndim != 2 or arr.shape != (n, n):
                raise ValueError(
                    f"from_matrices: {arg}: model.{name}: shape {arr.shape}, expected ({n}, {n}) for "
                    f"{n} DOFs"
                )
            bad = np.argwhere(~np.isfinite(arr))
            if len(bad):
                i, j = bad[0]
                raise ValueError(f"from_matrices: {arg}: model.{name}[{i}][{j}] is {arr[i, j]}")
            return arr.tolist()

        model: dict = {
            "dofs": [str(d) for d in dofs],
            "mass": matrix("mass", M),
            "stiffness": matrix("stiffness", K),
        }
        if C is not None:
            model["damping"] = matrix("damping", C)
        contacts = _args.table_list(where, "contacts", contacts)
        loads = _args.table_list(where, "loads", loads)
        if isinstance(freq_range_hz, (str, bytes)) or len(np.shape(freq_range_hz)) != 1 or len(freq_range_hz) != 2:
            raise TypeError(f"{where}: freq_range_hz: expected (start, end) in Hz, got {freq_range_hz!r}")
        f_start, f_end = (_args.number(where, f"freq_range_hz[{i}]", f) for i, f in enumerate(freq_range_hz))
        if outputs is not None:
            if isinstance(outputs, (str, bytes)) or not hasattr(outputs, "__iter__"):
                raise TypeError(f"{where}: outputs: expected a list of DOF names, got {_args.type_name(outputs)}")
            outputs = [_args.text(where, f"outputs[{i}]", o) for i, o in enumerate(outputs)]
        harmonics = _args.integer(where, "harmonics", harmonics, 1)
        samples = _args.integer(where, "samples", samples, 1)
        title = _args.text(where, "title", title)
        for key, table in (("analysis", analysis), ("effects", effects), ("limits", limits), ("accuracy", accuracy)):
            if table is not None:
                if not isinstance(table, Mapping):
                    raise TypeError(f"{where}: {key}: expected a dict, got {_args.type_name(table)}")
                _args.scene_values(where, key, table)
        static, harmonic = [], []
        for load in loads:
            (static if "value" in load else harmonic).append(dict(load))
        scene: dict = {
            "title": title,
            "model": model,
            "contacts": [dict(c) for c in contacts],
            "static_loads": static,
            "harmonic_loads": harmonic,
            "harmonics": {"max": harmonics, "samples": samples},
            "analysis": {
                "freq_start_hz": f_start,
                "freq_end_hz": f_end,
                **dict(analysis or {}),
            },
            "output": {"dofs": list(outputs) if outputs is not None else list(model["dofs"])},
        }
        for key, table in (("effects", effects), ("limits", limits), ("accuracy", accuracy)):
            if table is not None:
                scene[key] = dict(table)
        try:
            text = json.dumps(scene, allow_nan=False, default=_json_default)
        except ValueError as e:
            raise ValueError(f"from_matrices: {e} (NaN or infinity in a contact or load)") from None
        return cls(_native.scene_from_json(text, "<from_matrices>"), "<from_matrices>")

    # ---- changes and checks -------------------------------------------------------------

    def set(self, field: str, value: Any) -> "Scene":
        """Overrides one field by its dotted path, as ``--set FIELD=VALUE`` does
        (``"contacts.0.mu"``, ``"static_loads.0.value"``, ``"harmonics.max"``; array entries
        by index). ``None`` removes the field. Returns the scene itself (for chaining).

        Raises ``ValueError`` naming the override and the reason (unknown field, wrong type);
        the scene is then unchanged.
        """
        _args.text("Scene.set", "field", field)
        try:
            literal = _toml_literal(value)
        except TypeError as e:
            raise TypeError(f"Scene.set: {field}: {e}") from None
        assignment = f"{field}={literal}"
        _native.parse_scene(self._text, self._label, self._overrides + [assignment])
        self._overrides.append(assignment)
        return self

    def copy(self) -> "Scene":
        """An independent copy (same text, label and overrides)."""
        return Scene(self._text, self._label, self._overrides)

    def check(self) -> dict:
        """Validates the whole scene (``fricbound check``) and describes it: DOF, output,
        contact and side names, harmonics, unknowns, formulation, cost estimate, range.

        Raises ``ValueError`` whose message names the file, the field (dotted path, e.g.
        ``contacts[0].mu``) and the reason.
        """
        return _native.check(self._text, self._label, self._overrides)

    def to_toml(self) -> str:
        """The scene with its overrides applied, as canonical TOML text."""
        return _native.parse_scene(self._text, self._label, self._overrides)

    # ---- access -------------------------------------------------------------------------

    @property
    def text(self) -> str:
        """The scene text as read (before overrides)."""
        return self._text

    @property
    def label(self) -> str:
        """The scene's label: its file path, ``<string>``, ``<from_matrices>`` or the built-in
        paper scene's path."""
        return self._label

    @property
    def overrides(self) -> "list[str]":
        """The ``FIELD=VALUE`` overrides applied, in order."""
        return list(self._overrides)

    def _args(self) -> "tuple[str, str, list[str]]":
        return self._text, self._label, list(self._overrides)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Scene) and self.to_toml() == other.to_toml()

    def __hash__(self) -> int:
        return hash(self.to_toml())

    def __repr__(self) -> str:
        extra = f", {len(self._overrides)} overrides" if self._overrides else ""
        return f"Scene({self._label!r}{extra})"

    def __getstate__(self) -> dict:
        return {"text": self._text, "label": self._label, "overrides": list(self._overrides)}

    def __setstate__(self, state: dict) -> None:
        self._text = state["text"]
        self._label = state["label"]
        self._overrides = list(state["overrides"])


def _json_default(o: Any) -> Any:
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    raise TypeError(f"cannot write a {type(o).__name__} into a scene")
