# Type hints for the package rocklab (python/rocklab/__init__.py). All quantities SI.
import os
from typing import Any, Callable, Dict, List, NamedTuple, Optional, Union

import numpy as np

__version__: str

Source = Union[str, "os.PathLike[str]", Dict[str, Any]]
"""A file path, or a dict of the file's JSON (relative paths then resolve against the working
directory)."""

class PhysicsError(RuntimeError):
    """A physical blow-up (rocklab's exit status 3)."""

class Progress(NamedTuple):
    tag: str
    message: str
    fraction: Optional[float]
    elapsed_s: float
    eta_s: Optional[float]

ProgressCallback = Callable[[Progress], None]
Table = Any  # pandas.DataFrame when pandas is installed, else Dict[str, np.ndarray]

def executable() -> str: ...
def lab_tests() -> List[str]: ...

class Specimen:
    @staticmethod
    def load(path: Union[str, "os.PathLike[str]"]) -> "Specimen": ...
    def save(self, path: Union[str, "os.PathLike[str]"]) -> None: ...
    @property
    def report(self) -> Optional[Dict[str, Any]]: ...
    @property
    def meta(self) -> Dict[str, Any]: ...
    @property
    def grains(self) -> int: ...
    @property
    def dimension(self) -> int: ...

def genesis(card: Source, seed: Optional[int] = ..., threads: Optional[int] = ...,
            overrides: Optional[Dict[str, Any]] = ...,
            progress: Optional[ProgressCallback] = ...) -> Specimen: ...

class TestResult:
    results: Dict[str, Any]
    history: np.ndarray
    cracks: np.ndarray
    events: np.ndarray
    out_dir: Optional[str]
    def __getitem__(self, key: str) -> Any: ...
    @property
    def warnings(self) -> List[str]: ...

def test(protocol: Source, specimen: Union[Specimen, str, "os.PathLike[str]", None] = ...,
         out: Union[str, "os.PathLike[str]", None] = ..., threads: Optional[int] = ...,
         progress: Optional[ProgressCallback] = ...) -> TestResult: ...

class SuiteResult:
    summary: Table
    tests: Table
    results: Dict[str, Any]
    out_dir: Optional[str]
    @property
    def failed(self) -> bool: ...

def suite(suite: Source, out: Union[str, "os.PathLike[str]", None] = ...,
          threads: Optional[int] = ..., progress: Optional[ProgressCallback] = ...) -> SuiteResult: ...

class CalibrationResult:
    met: bool
    validation_met: bool
    card: Dict[str, Any]
    report: str
    summary: Dict[str, Any]
    out_dir: str

def calibrate(calibration: Source, out: Union[str, "os.PathLike[str]"], jobs: Optional[int] = ...,
              progress: Optional[ProgressCallback] = ...) -> CalibrationResult: ...

class RunResult:
    summary: Dict[str, Any]
    results: Dict[str, Any]
    history: np.ndarray
    out_dir: Optional[str]

def run(scene: Source, out: Union[str, "os.PathLike[str]", None] = ..., threads: Optional[int] = ...,
        progress: Optional[ProgressCallback] = ...) -> RunResult: ...
