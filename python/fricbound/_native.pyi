"""Type stubs of the extension module ``fricbound._native`` (Rust, PyO3). Use the public API of
``fricbound`` instead; these functions take a scene as (text, label, overrides)."""

from typing import Any, Callable, Dict, List, Optional, Tuple

import numpy as np
import numpy.typing as npt

__version__: str

class SolveError(RuntimeError): ...

_Progress = Optional[Callable[[Dict[str, Any]], Any]]

def paper_scene() -> Tuple[str, str]: ...
def parse_scene(text: str, label: str, overrides: List[str]) -> str: ...
def scene_from_json(json: str, label: str) -> str: ...
def check(text: str, label: str, overrides: List[str]) -> Dict[str, Any]: ...
def run(text: str, label: str, overrides: List[str], progress: _Progress = None) -> Dict[str, Any]: ...
def limits(text: str, label: str, overrides: List[str], progress: _Progress = None) -> Dict[str, Any]: ...
def sweep(text: str, label: str, overrides: List[str], progress: _Progress = None) -> Dict[str, Any]: ...
def modes(text: str, label: str, overrides: List[str], count: int, case: str) -> Dict[str, Any]: ...
def nonlinear_modes(text: str, label: str, overrides: List[str]) -> Dict[str, Any]: ...
def reduce(
    n: int,
    k_indptr: npt.NDArray[np.int64],
    k_indices: npt.NDArray[np.int64],
    k_data: npt.NDArray[np.float64],
    m_indptr: npt.NDArray[np.int64],
    m_indices: npt.NDArray[np.int64],
    m_data: npt.NDArray[np.float64],
    boundary: List[int],
    modes: int,
    recover: List[int],
) -> Dict[str, Any]: ...
def verify(
    text: str,
    label: str,
    overrides: List[str],
    freqs_hz: List[float],
    steps_per_period: Optional[int] = None,
    max_periods: Optional[int] = None,
) -> Dict[str, Any]: ...
def linear(
    text: str, label: str, overrides: List[str], case: str, points: Optional[int] = None
) -> Dict[str, Any]: ...
def accuracy_study(
    text: str, label: str, overrides: List[str], quick: bool, progress: _Progress = None
) -> Dict[str, Any]: ...
