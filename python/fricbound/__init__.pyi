"""Type stubs of the public API of ``fricbound`` (see the docstrings of the modules)."""

import os
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str
MAX_INLINE_DOFS: int

class SolveError(RuntimeError): ...

Progress = Optional[Callable[[Dict[str, Any]], Any]]
_F = npt.NDArray[np.float64]

class Scene:
    def __init__(self, text: str, label: str = ..., overrides: Sequence[str] = ...) -> None: ...
    @classmethod
    def from_toml(cls, path_or_text: Union[str, "os.PathLike[str]"]) -> "Scene": ...
    @classmethod
    def paper(cls) -> "Scene": ...
    @classmethod
    def from_matrices(
        cls,
        M: Any,
        C: Any,
        K: Any,
        *,
        dofs: Sequence[str],
        contacts: Sequence[Mapping[str, Any]] = ...,
        loads: Sequence[Mapping[str, Any]] = ...,
        freq_range_hz: Tuple[float, float],
        outputs: Optional[Sequence[str]] = ...,
        harmonics: int = ...,
        samples: int = ...,
        title: str = ...,
        analysis: Optional[Mapping[str, Any]] = ...,
        effects: Optional[Mapping[str, Any]] = ...,
        limits: Optional[Mapping[str, Any]] = ...,
        accuracy: Optional[Mapping[str, Any]] = ...,
    ) -> "Scene": ...
    def set(self, field: str, value: Any) -> "Scene": ...
    def copy(self) -> "Scene": ...
    def check(self) -> Dict[str, Any]: ...
    def to_toml(self) -> str: ...
    @property
    def text(self) -> str: ...
    @property
    def label(self) -> str: ...
    @property
    def overrides(self) -> List[str]: ...

class ContinuationPath:
    freq_hz: _F
    amplitudes: _F
    max_displacement: _F
    states: npt.NDArray[np.str_]
    coefficients: _F
    newton_iterations: npt.NDArray[np.int64]
    residual: _F
    trunc_err: Optional[_F]
    sampling_err: Optional[_F]
    stable: Optional[npt.NDArray[np.bool_]]
    floquet_re: Optional[_F]
    floquet_freq_hz: Optional[_F]
    stability_method: Optional[List[str]]
    stability_reliable: Optional[npt.NDArray[np.bool_]]
    dofs: List[str]
    outputs: List[str]
    contacts: List[str]
    blocks: List[str]
    status: str
    @property
    def complete(self) -> bool: ...
    def __len__(self) -> int: ...
    def amplitude(self, dof: str) -> _F: ...
    def coefficient(self, dof: str, block: str) -> _F: ...
    def to_pandas(self) -> Any: ...

class FrfResult(ContinuationPath):
    turning_points_hz: List[float]
    jumps: List[Dict[str, Any]]
    rejected_steps: int
    elapsed_s: float
    csv: str
    peaks: Dict[str, Any]
    peaks_csv: str
    def write_csv(self, path: str) -> None: ...
    def write_peaks_csv(self, path: str) -> None: ...
    def resonances(self, dof: str) -> Dict[str, Any]: ...
    def peaks_to_pandas(self) -> Any: ...

class Curve(ContinuationPath):
    name: str
    contact_states: List[float]
    peak: Optional[Dict[str, Any]]
    turning_points_hz: List[float]

class LimitsResult:
    limits: List[Curve]
    intermediate: List[Curve]
    grid_freq_hz: _F
    grid_lower: _F
    grid_upper: _F
    grid_amplitudes: _F
    grid_regime: npt.NDArray[np.str_]
    bounds: Optional[Dict[str, float]]
    scanned: List[Dict[str, Any]]
    variability: Dict[str, float]
    envelope: Optional[Dict[str, Any]]
    unfinished: List[str]
    status: str
    @property
    def complete(self) -> bool: ...
    @property
    def curves(self) -> List[Curve]: ...
    def to_pandas(self) -> Any: ...

class SweepResult:
    parameter: str
    unit: str
    series_parameter: Optional[str]
    value: _F
    series: _F
    cases: List[str]
    peak_amplitude: _F
    peak_freq_hz: _F
    peak_refined: _F
    failures: List[List[str]]
    status: str
    @property
    def complete(self) -> bool: ...
    def limit_peaks(self) -> Tuple[_F, _F]: ...
    def to_pandas(self) -> Any: ...

class VerifyResult:
    STAY_TOLERANCE: float
    cases: List[Dict[str, Any]]
    outputs: List[str]
    status: str
    @property
    def complete(self) -> bool: ...
    def to_pandas(self) -> Any: ...

class AccuracyStudy:
    curve: List[str]
    role: List[str]
    group: List[str]
    setting: List[str]
    setting_status: List[str]
    unknowns: _F
    points: _F
    newton_iterations: _F
    time_s: _F
    curve_l2: _F
    peak_amp_err: _F
    peak_freq_err: _F
    pareto: List[bool]
    references: Dict[str, Dict[str, Any]]
    outputs: List[str]
    status: str
    @property
    def complete(self) -> bool: ...
    def rows(self, curve: Optional[str] = ..., role: str = ...) -> npt.NDArray[np.int_]: ...
    def pareto_front(self, curve: Optional[str] = ...) -> List[str]: ...
    def to_pandas(self) -> Any: ...

class LinearResult:
    case: str
    freq_hz: _F
    amplitudes: _F
    outputs: List[str]
    def amplitude(self, dof: str) -> _F: ...
    def to_pandas(self) -> Any: ...

class ModesResult:
    case: str
    frequency_hz: _F
    eigenvalue: _F
    rigid: npt.NDArray[np.bool_]
    shapes: _F
    method: str
    dofs: List[str]
    def to_pandas(self) -> Any: ...

class NonlinearMode:
    mode: int
    linear_freq_hz: float
    linear_damping_ratio: float
    status: str
    modal_amplitude: _F
    amplitude: _F
    freq_hz: _F
    damping_ratio: _F
    xi: _F
    dissipated_energy: _F
    friction_energy: _F
    states: List[List[str]]
    coefficients: _F
    predicted_peak: Optional[Dict[str, float]]
    def to_pandas(self) -> Any: ...

class NonlinearModesResult:
    status: str
    complete: bool
    dof: str
    amplitude_range: List[float]
    case_names: List[str]
    cases: Dict[str, Any]
    band: Optional[Dict[str, Any]]
    freq_hz: _F
    damping_ratio: _F
    amplitude: _F
    def to_pandas(self) -> Any: ...

class ReducedModel:
    stiffness: _F
    mass: _F
    boundary: List[int]
    n_modes: int
    modal_frequencies_hz: _F
    recovery: _F
    recover: List[int]

def run(scene: Union[Scene, str], progress: Progress = ...) -> FrfResult: ...
def limits(scene: Union[Scene, str], progress: Progress = ...) -> LimitsResult: ...
def sweep(
    scene: Union[Scene, str],
    field: Optional[str] = ...,
    values: Optional[Sequence[float]] = ...,
    *,
    scale: float = ...,
    offset: float = ...,
    parameter: Optional[str] = ...,
    unit: str = ...,
    progress: Progress = ...,
) -> SweepResult: ...
def verify(
    scene: Union[Scene, str],
    freqs_hz: Sequence[float],
    steps_per_period: Optional[int] = ...,
    max_periods: Optional[int] = ...,
) -> VerifyResult: ...
def accuracy_study(
    scene: Union[Scene, str], quick: bool = ..., progress: Progress = ...
) -> AccuracyStudy: ...
def linear(scene: Union[Scene, str], case: str = ..., points: Optional[int] = ...) -> LinearResult: ...
def modes(scene: Union[Scene, str], count: int = ..., case: str = ...) -> ModesResult: ...
def nonlinear_modes(
    scene: Union[Scene, str],
    mode: Optional[int] = ...,
    mode_freq_hz: Optional[float] = ...,
    dof: Optional[str] = ...,
    amplitude: Optional[Sequence[float]] = ...,
    max_points: Optional[int] = ...,
) -> NonlinearModesResult: ...
def reduce(
    K: Any, M: Any, boundary: Sequence[int], modes: int, recover: Optional[Sequence[int]] = ...
) -> ReducedModel: ...
