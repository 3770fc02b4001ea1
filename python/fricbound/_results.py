"""Result classes: numpy arrays with names, a ``to_pandas()`` when pandas is installed, and
plain pickling (they hold only numpy arrays, lists and scalars)."""

from __future__ import annotations

from typing import Any, Dict, List, Optional

import numpy as np


def _pandas():
    try:
        import pandas as pd
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError("to_pandas() needs pandas: pip install pandas") from e
    return pd


class _Result:
    """Common part: the fields of the library's result as attributes."""

    def __init__(self, fields: Dict[str, Any]):
        self.__dict__.update(fields)

    def __getstate__(self) -> dict:
        return dict(self.__dict__)

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)

    @property
    def complete(self) -> bool:
        """Whether the run covered what was asked for (``status == "complete"``); otherwise
        ``status`` is ``incomplete: <reason>``, as in the CLI's JSON files (exit code 3)."""
        return self.status == "complete"


class ContinuationPath(_Result):
    """The converged points of one continuation path.

    Attributes (n points, ``outputs`` response DOFs, ``contacts`` contact points):

    - ``freq_hz`` (n,): excitation frequency (Hz);
    - ``amplitudes`` (n, outputs): first-harmonic amplitude √(c₁² + s₁²) (m);
    - ``max_displacement`` (n, outputs): the largest displacement over the period, max |q(τ)|,
      static part included (m): the ``<dof>_peak`` column of ``frf.csv`` (called ``peaks``
      until this release; the refined resonance peaks are :attr:`FrfResult.peaks`);
    - ``states`` (n, contacts) str: ``stuck``, ``stick-slip``, ``stick-slip-liftoff``, ``open``;
    - ``coefficients`` (n, DOFs × blocks): Fourier coefficients (m), harmonic-major: the value
      of DOF ``d`` in block ``b`` (``blocks``: ``0``, ``c1``, ``s1``, ...) is column
      ``b * len(dofs) + d`` (see :meth:`coefficient`);
    - ``newton_iterations`` (n,), ``residual`` (n,): Newton iterations and final residual
      relative to the load norm;
    - ``trunc_err``, ``sampling_err`` (n, outputs) or None: estimated relative error of the
      amplitudes from harmonic truncation and AFT sampling (``[accuracy]``, on by default);
      ``estimate_harmonic`` (n,) int: the highest harmonic of the extended set the truncation
      estimate comes from (2H + 1, or 4H + 3 where widened; 0 where not formed), and
      ``estimate_method`` (n,) str: ``step``, ``solved``, ``unsized`` (the error is not sized),
      ``unsolved`` (not sized: ``accuracy.beyond_linear_range = "flag"``), ``converged`` (the
      point already solves the extended harmonic balance within the Newton tolerance: both
      estimates 0) or ``none``, as the CLI's ``frf.csv``;
    - ``stable`` (n,) bool, ``floquet_re`` (n,) 1/s, ``floquet_freq_hz`` (n,) or None: the
      stability verdict, when the scene sets ``analysis.stability = true``;
      ``stability_method`` (n,) str: which method gave it (``hill``, ``monodromy``, or
      ``failed``: no verdict, ``stable`` is then False and meaningless), set by
      ``analysis.stability_method``; ``stability_reliable`` (n,) bool: whether the verdict can
      be trusted (Hill's is not on stick-slip points).
    """

    trunc_err: Optional[np.ndarray] = None
    sampling_err: Optional[np.ndarray] = None
    estimate_harmonic: Optional[np.ndarray] = None
    estimate_method: Optional[List[str]] = None
    stable: Optional[np.ndarray] = None
    floquet_re: Optional[np.ndarray] = None
    floquet_freq_hz: Optional[np.ndarray] = None
    stability_method: Optional[List[str]] = None
    stability_reliable: Optional[np.ndarray] = None

    def __init__(self, fields: Dict[str, Any], names: Dict[str, Any]):
        fields = dict(fields)
        states = fields.get("states", [])
        n_contacts = len(names.get("contacts", []))
        fields["states"] = (
            np.array(states, dtype=str) if len(states) else np.empty((0, n_contacts), dtype=str)
        )
        for key in ("dofs", "outputs", "contacts", "blocks"):
            fields.setdefault(key, names.get(key, []))
        super().__init__(fields)

    def __len__(self) -> int:
        return len(self.freq_hz)

    def amplitude(self, dof: str) -> np.ndarray:
        """First-harmonic amplitude (m) of output DOF ``dof`` at every point."""
        return self.amplitudes[:, self.outputs.index(dof)]

    def coefficient(self, dof: str, block: str) -> np.ndarray:
        """Fourier coefficient (m) of DOF ``dof`` in block ``block`` (``"0"``, ``"c1"``,
        ``"s1"``, ...) at every point."""
        b = self.blocks.index(block)
        d = self.dofs.index(dof)
        return self.coefficients[:, b * len(self.dofs) + d]

    def to_pandas(self):
        """A DataFrame with the columns of the CLI's ``frf.csv``: ``freq_hz``,
        ``<dof>_amp``, ``<dof>_peak`` (:attr:`max_displacement`) per output, ``<contact>_state`` per contact,
        ``newton_iters``, then ``<dof>_trunc_err``, ``<dof>_sampling_err``,
        ``estimate_harmonic``, ``estimate_method`` and ``stable``,
        ``floquet_re``, ``floquet_freq_hz``, ``stability_method``, ``stability_reliable``
        when present."""
        pd = _pandas()
        cols: Dict[str, Any] = {"freq_hz": self.freq_hz}
        for k, name in enumerate(self.outputs):
            cols[f"{name}_amp"] = self.amplitudes[:, k]
            cols[f"{name}_peak"] = self.max_displacement[:, k]
        for k, name in enumerate(self.contacts):
            cols[f"{name}_state"] = self.states[:, k] if len(self) else []
        cols["newton_iters"] = self.newton_iterations
        if self.trunc_err is not None:
            for k, name in enumerate(self.outputs):
                cols[f"{name}_trunc_err"] = self.trunc_err[:, k]
                cols[f"{name}_sampling_err"] = self.sampling_err[:, k]
            cols["estimate_harmonic"] = self.estimate_harmonic
            cols["estimate_method"] = self.estimate_method
        if self.stable is not None:
            cols["stable"] = self.stable
            cols["floquet_re"] = self.floquet_re
            cols["floquet_freq_hz"] = self.floquet_freq_hz
            cols["stability_method"] = self.stability_method
            cols["stability_reliable"] = self.stability_reliable
        return pd.DataFrame(cols)


_PATH_KEYS = (
    "freq_hz",
    "amplitudes",
    "max_displacement",
    "coefficients",
    "states",
    "newton_iterations",
    "residual",
    "trunc_err",
    "sampling_err",
    "estimate_harmonic",
    "estimate_method",
    "stable",
    "floquet_re",
    "floquet_freq_hz",
    "stability_method",
    "stability_reliable",
)


class FrfResult(ContinuationPath):
    """One nonlinear frequency response (:func:`fricbound.run`): the points of
    :class:`ContinuationPath`, plus

    - ``status``: ``complete`` or ``incomplete: <reason>`` (as ``solution.json``);
    - ``turning_points_hz``, ``jumps``, ``rejected_steps``, ``elapsed_s``; each jump (where
      the path turned back at a fold and left the range below the start, the run went on on
      a branch found past the highest frequency reached) is a dict ``from_hz`` (the highest
      frequency before it), ``to_hz`` (the lowest the branch after it reached, followed back
      down) and ``first_point`` (index of that branch's first point);
    - ``csv``: the run's ``frf.csv`` exactly as the CLI writes it (:meth:`write_csv`);
    - ``peaks``: the refined resonances and anti-resonances of every output, as the CLI's
      ``peaks.csv`` (one entry per extremum, ordered by output, then along the path): a dict
      of columns named as that file's, ``dof``, ``kind`` (``resonance`` or
      ``anti-resonance``), ``freq_hz`` (Hz) and ``amplitude`` (m) of the refined extremum,
      ``refined`` (False where the refinement failed or the extremum is a branch's first or
      last point: the values are then the path point's), ``at_branch_end`` (a resonance
      standing out only toward a break between branches), ``path_index``, ``path_freq_hz``,
      ``path_amplitude`` (the path point it was refined from), ``<contact>_state`` per
      contact; :meth:`peaks_to_pandas` gives it as a DataFrame, :meth:`resonances` the
      resonances of one output; ``peaks_csv``: that file's text (:meth:`write_peaks_csv`).
    """

    def __init__(self, d: Dict[str, Any]):
        d = dict(d)
        peaks = dict(d.get("peaks", {}))
        for key in ["dof", "kind"] + [f"{c}_state" for c in d.get("contacts", [])]:
            if key in peaks:
                peaks[key] = np.array(peaks[key], dtype=str)
        d["peaks"] = peaks
        super().__init__(d, d)

    def write_csv(self, path: str) -> None:
        """Writes ``frf.csv`` (the CLI's columns and number format) to ``path``."""
        with open(path, "w", encoding="utf-8") as f:
            f.write(self.csv)

    def write_peaks_csv(self, path: str) -> None:
        """Writes ``peaks.csv`` (the CLI's columns and number format) to ``path``."""
        with open(path, "w", encoding="utf-8") as f:
            f.write(self.peaks_csv)

    def resonances(self, dof: str) -> "Dict[str, np.ndarray]":
        """The refined resonances (``kind == "resonance"``) of output ``dof``: the columns of
        :attr:`peaks` cut to their rows."""
        rows = (self.peaks["kind"] == "resonance") & (self.peaks["dof"] == dof)
        return {k: np.asarray(v)[rows] for k, v in self.peaks.items()}

    def peaks_to_pandas(self):
        """:attr:`peaks` as a DataFrame, the columns of the CLI's ``peaks.csv``."""
        return _pandas().DataFrame(self.peaks)

    def __repr__(self) -> str:
        return f"FrfResult({len(self)} points, {self.status})"


class Curve(ContinuationPath):
    """A limit or intermediate curve of a limit analysis: the points of :class:`ContinuationPath`, plus
    ``name`` (``m+1``, ``m-1``, ...), ``contact_states`` (m per contact), ``status``,
    ``turning_points_hz`` and ``peak`` (dict ``freq_hz``, ``amplitude`` (m),
    ``refined``, ``states``; None when no point lies in the peak window)."""

    def __init__(self, d: Dict[str, Any], names: Dict[str, Any]):
        points = d["points"]
        fields = {k: v for k, v in d.items() if k != "points"}
        fields.update({k: points[k] for k in _PATH_KEYS if k in points})
        super().__init__(fields, names)

    def __repr__(self) -> str:
        return f"Curve({self.name!r}, {len(self)} points, {self.status})"


class LimitsResult(_Result):
    """A limit analysis (:func:`fricbound.limits`, the paper's two-point method):

    - ``limits``: the two limit curves (:class:`Curve`, m = +1 and m = −1 on every point);
      ``intermediate``: the intermediate curves;
    - ``grid_freq_hz`` (g,), ``grid_lower``, ``grid_upper`` (g,): the band between the limit
      curves on the common grid (m); ``grid_amplitudes`` (g, limit curves);
      ``grid_regime`` (g,) str: ``unique``, ``multiple`` or ``unknown``;
    - ``bounds``: the bound check of a ``bound_scan`` (largest excess above / below, m) or None;
      ``scanned``: the scanned cases' peaks;
    - ``variability``: upper and lower peak (m), their ratio, peak-frequency change (%),
      widest band; ``status``, ``unfinished``;
    - ``envelope`` (with ``[limits] envelope = "sides"`` or ``"points"``, else None): a dict
      with ``mode``, ``groups`` (the sides or points, the order of every m), ``freq_hz`` (g,),
      ``min``, ``max`` (g, outputs): the smallest and largest amplitude over all initial
      states (m, NaN where none was solved), ``min_m``, ``max_m`` (g, outputs, groups): the m
      attaining them, ``check``: where and by how much the limit curves fail to bound it
      (relative excesses, ``above_at``/``below_at`` = (frequency, m)), ``solves``,
      ``unsolved``, ``elapsed_s``.
    """

    def __init__(self, d: Dict[str, Any]):
        fields = dict(d)
        fields["limits"] = [Curve(c, d) for c in d["limits"]]
        fields["intermediate"] = [Curve(c, d) for c in d["intermediate"]]
        fields["grid_regime"] = np.array(d["grid_regime"], dtype=str)
        super().__init__(fields)

    @property
    def curves(self) -> "List[Curve]":
        """Limit curves, then intermediate ones."""
        return list(self.limits) + list(self.intermediate)

    def to_pandas(self):
        """The common grid as a DataFrame: ``freq_hz``, ``lower``, ``upper``,
        ``<case>_amp`` per limit curve, ``regime``, and with an envelope ``envelope_min``,
        ``envelope_max`` (first output DOF)."""
        pd = _pandas()
        cols: Dict[str, Any] = {
            "freq_hz": self.grid_freq_hz,
            "lower": self.grid_lower,
            "upper": self.grid_upper,
        }
        for k, c in enumerate(self.limits):
            cols[f"{c.name}_amp"] = self.grid_amplitudes[:, k]
        cols["regime"] = self.grid_regime
        env = getattr(self, "envelope", None)
        if env is not None and len(env["freq_hz"]) == len(self.grid_freq_hz):
            cols["envelope_min"] = env["min"][:, 0]
            cols["envelope_max"] = env["max"][:, 0]
        return pd.DataFrame(cols)

    def __repr__(self) -> str:
        return f"LimitsResult({len(self.curves)} curves, {self.status})"


class SweepResult(_Result):
    """A sweep of the limit analysis (:func:`fricbound.sweep`): per value (``value``,
    ``series``) and case (``cases``: the ``limit_cases`` limit cases, then the intermediate
    ones) ``peak_amplitude`` (m) and ``peak_freq_hz`` of the resonance peak (NaN where the case
    failed or did not cover the range), ``peak_refined``; ``failures`` per value, ``status``,
    ``peaks_from``. On a forced-response scene the limit cases are m = +1 and m = -1; on a
    nonlinear-mode scene every combination of m = +1 / -1 per damper side, and the peaks are
    those the mode of each case predicts.
    """

    def limit_peaks(self) -> "tuple[np.ndarray, np.ndarray]":
        """Upper and lower limit peak amplitude (m) per value (the largest and smallest over
        the limit cases), as the paper's optimal curves (Fig. 16a)."""
        limits = self.peak_amplitude[:, : self.limit_cases]
        return np.max(limits, axis=1), np.min(limits, axis=1)

    def to_pandas(self):
        """One row per value: ``<parameter>`` (and the series parameter), then
        ``<case>_amp``, ``<case>_freq_hz``, ``<case>_refined`` per case, ``failures``."""
        pd = _pandas()
        cols: Dict[str, Any] = {}
        if self.series_parameter is not None:
            cols[self.series_parameter] = self.series
        cols[self.parameter] = self.value
        for k, c in enumerate(self.cases):
            cols[f"{c}_amp"] = self.peak_amplitude[:, k]
            cols[f"{c}_freq_hz"] = self.peak_freq_hz[:, k]
            cols[f"{c}_refined"] = self.peak_refined[:, k].astype(bool)
        cols["failures"] = ["; ".join(f) for f in self.failures]
        return pd.DataFrame(cols)

    def __repr__(self) -> str:
        return f"SweepResult({self.parameter}: {len(self.value)} values, {self.status})"


class VerifyResult(_Result):
    """Time integration of harmonic-balance points (:func:`fricbound.verify`), one entry of
    ``cases`` per frequency: ``freq_hz``, ``hbm_amplitudes`` and ``amplitudes`` (first-harmonic
    amplitude of each output from the HBM and from the time integration at dt/2, m),
    ``coarse_amplitudes`` (at dt), ``hbm_difference`` (largest relative difference),
    ``dt_change``, ``periods``, ``settled``, ``nonharmonic_energy``, ``hill_stable`` and
    ``floquet_re`` (None where Hill's method does not apply), ``stays`` (the motion stays within
    ``STAY_TOLERANCE`` = 1e-3 of the HBM amplitude, as ``fricbound verify`` reports), and
    ``last_period`` (outputs × steps, m). ``status`` is what ``fricbound verify`` reports:
    ``complete``, or ``incomplete: <freq> Hz did not settle, ...`` when a time integration did
    not reach a periodic state within ``max_periods`` (the CLI's exit code 3); a motion that
    settled away from the HBM point (``stays`` False) is a result, not incomplete. A frequency
    whose harmonic balance does not converge raises :class:`fricbound.SolveError` instead
    (the CLI reports it as ``<freq> Hz failed``)."""

    STAY_TOLERANCE = 1e-3

    def __init__(self, cases: List[Dict[str, Any]], outputs: List[str], status: str):
        for c in cases:
            c["stays"] = bool(c["hbm_difference"] < self.STAY_TOLERANCE)
            c["last_period"] = np.array(c["last_period"])
        super().__init__({"cases": cases, "outputs": outputs, "status": status})

    def to_pandas(self):
        """One row per frequency: ``freq_hz``, ``<dof>_hbm_amp`` and ``<dof>_time_amp`` per
        output, ``hbm_difference``, ``dt_change``, ``periods``, ``settled``, ``stays``,
        ``hill_stable``, ``floquet_re``."""
        pd = _pandas()
        rows = []
        for c in self.cases:
            row: Dict[str, Any] = {"freq_hz": c["freq_hz"]}
            for k, name in enumerate(self.outputs):
                row[f"{name}_hbm_amp"] = c["hbm_amplitudes"][k]
                row[f"{name}_time_amp"] = c["amplitudes"][k]
            for key in ("hbm_difference", "dt_change", "periods", "settled", "stays", "hill_stable", "floquet_re"):
                row[key] = c[key]
            rows.append(row)
        return pd.DataFrame(rows)

    def __repr__(self) -> str:
        return f"VerifyResult({[c['freq_hz'] for c in self.cases]} Hz)"


class LinearResult(_Result):
    """A linear reference (:func:`fricbound.linear`): ``freq_hz`` (points,) and
    ``amplitudes`` (points, outputs) in m, ``case`` (``open`` or ``stuck``), ``outputs``."""

    status = "complete"

    def amplitude(self, dof: str) -> np.ndarray:
        """First-harmonic amplitude (m) of output DOF ``dof``."""
        return self.amplitudes[:, self.outputs.index(dof)]

    def to_pandas(self):
        """``freq_hz`` and ``<dof>_amp`` per output, as the CLI's ``linear_<case>.csv``."""
        pd = _pandas()
        cols: Dict[str, Any] = {"freq_hz": self.freq_hz}
        for k, name in enumerate(self.outputs):
            cols[f"{name}_amp"] = self.amplitudes[:, k]
        return pd.DataFrame(cols)

    def __repr__(self) -> str:
        return f"LinearResult({self.case}, {len(self.freq_hz)} points)"


class ModesResult(_Result):
    """Natural modes (:func:`fricbound.modes`): ``frequency_hz``, ``eigenvalue`` (rad²/s²),
    ``rigid``, ``shapes`` (DOFs × modes, mass-normalised), ``case`` (``open``/``stuck``),
    ``method`` (``dense`` or ``lanczos``), ``dofs``."""

    status = "complete"

    def to_pandas(self):
        """One row per mode: ``mode``, ``frequency_hz``, ``eigenvalue``, ``rigid``."""
        pd = _pandas()
        return pd.DataFrame(
            {
                "mode": np.arange(1, len(self.frequency_hz) + 1),
                "frequency_hz": self.frequency_hz,
                "eigenvalue": self.eigenvalue,
                "rigid": self.rigid,
            }
        )

    def __repr__(self) -> str:
        return f"ModesResult({self.case}: {np.round(self.frequency_hz, 3).tolist()} Hz)"


class NonlinearMode(_Result):
    """One nonlinear mode (a case of :class:`NonlinearModesResult`), one entry per continuation
    point, rising along the path: ``modal_amplitude`` a (kg^½·m; the first-harmonic motion is
    a ψ₁ with ψ₁ᵀMψ₁ = 1), ``amplitude`` (first-harmonic amplitude at the mode's DOF, m),
    ``freq_hz``, ``damping_ratio`` (D = ξ/2ω), ``xi`` (the artificial damping ξ, 1/s),
    ``dissipated_energy`` and ``friction_energy`` (per cycle, J), ``states`` (points ×
    contacts, str), ``coefficients`` (points × DOFs·blocks, m, harmonic-major as
    :attr:`ContinuationPath.coefficients`), ``newton_iterations``; and ``mode`` (its number),
    ``linear_freq_hz``, ``linear_damping_ratio`` (the linear mode at rest), ``status``, and
    ``predicted_peak`` (``amplitude`` m, ``freq_hz``, ``modal_amplitude``: the resonance peak
    under the scene's harmonic loads by single-nonlinear-mode theory) or None. With the error
    estimate (``accuracy.estimate``, on by default): ``freq_trunc_err``,
    ``damping_trunc_err``, ``amplitude_trunc_err`` (the relative changes of the frequency,
    damping ratio and amplitude at the DOF when the harmonics are raised to 2H + 1; NaN where
    not sized), else None."""

    predicted_peak: Optional[dict] = None
    freq_trunc_err: Optional[np.ndarray] = None
    damping_trunc_err: Optional[np.ndarray] = None
    amplitude_trunc_err: Optional[np.ndarray] = None

    def to_pandas(self):
        """One row per point: ``modal_amplitude``, ``amplitude``, ``freq_hz``,
        ``damping_ratio``, ``xi``, ``dissipated_energy``, ``friction_energy``,
        ``<contact>_state``, and the error estimate's three columns when it was computed."""
        pd = _pandas()
        columns = {
            k: getattr(self, k)
            for k in (
                "modal_amplitude",
                "amplitude",
                "freq_hz",
                "damping_ratio",
                "xi",
                "dissipated_energy",
                "friction_energy",
            )
        }
        for j, name in enumerate(self.contacts):
            columns[f"{name}_state"] = [row[j] for row in self.states]
        for k in ("freq_trunc_err", "damping_trunc_err", "amplitude_trunc_err"):
            if getattr(self, k) is not None:
                columns[k] = getattr(self, k)
        return pd.DataFrame(columns)

    def __repr__(self) -> str:
        return f"NonlinearMode(mode {self.mode}, {len(self.freq_hz)} points, {self.status})"


class NonlinearModesResult(_Result):
    """The nonlinear mode(s) of a scene (:func:`fricbound.nonlinear_modes`, as ``fricbound run``
    writes ``modes_nl.csv``): ``cases`` maps each case name (``scene`` without ``[limits]``;
    ``m+1``, ``m-1``, per-side combinations and the intermediate cases with it) to a
    :class:`NonlinearMode` (or, for a failed case, a dict with its ``status``); ``case_names``
    in order; ``dof`` and ``amplitude_range`` (m); ``status``; ``band`` (with ``[limits]``):
    ``amplitude``, ``freq_min_hz``, ``freq_max_hz``, ``damping_min``, ``damping_max`` arrays
    and ``wide`` stretches [from, to] (m). The arrays of the first case are also attributes of
    the result itself (``result.freq_hz`` is ``result.cases[result.case_names[0]].freq_hz``)."""

    band: Optional[dict] = None

    def __init__(self, fields: Dict[str, Any]):
        names = {k: fields[k] for k in ("dofs", "outputs", "contacts")}
        cases = {}
        for name, entry in fields.pop("cases").items():
            cases[name] = NonlinearMode({**entry, **names}) if "freq_hz" in entry else entry
        fields["cases"] = cases
        super().__init__(fields)
        first = cases.get(self.case_names[0])
        if isinstance(first, NonlinearMode):
            for k, v in first.__dict__.items():
                if k not in self.__dict__:
                    self.__dict__[k] = v

    def to_pandas(self):
        """One row per point of every case, with a ``case`` column first."""
        pd = _pandas()
        frames = []
        for name in self.case_names:
            mode = self.cases[name]
            if isinstance(mode, NonlinearMode):
                frame = mode.to_pandas()
                frame.insert(0, "case", name)
                frames.append(frame)
        return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()

    def __repr__(self) -> str:
        return f"NonlinearModesResult({', '.join(self.case_names)}: {self.status})"


class ReducedModel(_Result):
    """A Craig-Bampton reduced model (:func:`fricbound.reduce`): ``stiffness`` and ``mass``
    (r × r, r = boundary DOFs + modes), ``boundary`` (full indices of the first coordinates),
    ``n_modes``, ``modal_frequencies_hz`` of the fixed-interface modes, and ``recovery``
    (rows × r: the full DOF ``recover[i]`` is ``recovery[i] @ q``)."""

    status = "complete"

    def __repr__(self) -> str:
        return f"ReducedModel({len(self.boundary)} boundary DOFs + {self.n_modes} modes)"


class AccuracyStudy(_Result):
    """The accuracy study (:func:`fricbound.accuracy_study`, as ``fricbound study accuracy``):
    one row per (curve, setting), each curve's ``reference`` and ``check`` first (``role``),
    then the settings varied one at a time (``role == "setting"``). Columns (numpy arrays or
    lists, one entry per row): ``curve`` (``frf``, or the limit case ``m+1``, ``m-1``, a
    ``[[limits.cases]]`` name), ``role``, ``group`` (``harmonics``, ``samples``, ``tolerance``,
    ``modes``, ``effect``, ``reference``), ``setting`` (label), ``setting_status``,
    ``unknowns``, ``points``, ``newton_iterations``, ``time_s`` (wall time of the
    continuation, settings run in parallel), ``curve_l2`` (relative L2 error of the first
    output's amplitude against the curve's reference), ``peak_amp_err`` and ``peak_freq_err``
    (largest relative error of the resonance peaks' amplitude and frequency; NaN where a peak
    is missing), ``pareto`` (on the curve's Pareto front of time against peak error). Per
    curve, ``references[curve]`` holds the reference's ``setting``, ``peaks_hz``,
    ``peaks_amp`` and how far its check differs (``check_curve_l2``,
    ``check_peak_amp_err``)."""

    def rows(self, curve: Optional[str] = None, role: str = "setting") -> np.ndarray:
        """Indices of the rows of ``curve`` (every curve when None) with ``role``."""
        return np.array(
            [
                i
                for i, (c, r) in enumerate(zip(self.curve, self.role))
                if (curve is None or c == curve) and r == role
            ],
            dtype=int,
        )

    def pareto_front(self, curve: Optional[str] = None) -> "List[str]":
        """Labels of the settings on the Pareto front of ``curve`` (the first curve when
        None), fastest first."""
        curve = curve if curve is not None else self.curve[0]
        idx = [i for i in self.rows(curve) if self.pareto[i]]
        idx.sort(key=lambda i: self.time_s[i])
        return [self.setting[i] for i in idx]

    def to_pandas(self):
        """One row per (curve, setting), the columns above (as ``study.csv``, with the largest
        peak errors)."""
        pd = _pandas()
        cols = [
            "curve", "role", "group", "setting", "setting_status", "unknowns", "points",
            "newton_iterations", "time_s", "curve_l2", "peak_amp_err", "peak_freq_err", "pareto",
        ]
        return pd.DataFrame({c: getattr(self, c) for c in cols})

    def __repr__(self) -> str:
        curves = list(dict.fromkeys(self.curve))
        return f"AccuracyStudy({len(self.curve)} rows, curves {curves})"
