"""Type stubs of the native module (the documented interface is `rothe`)."""

from os import PathLike
from typing import List, Optional, Tuple

import numpy as np

__version__: str

class Error(ValueError):
    """An error of rothe: bad input (the message names the field) or a failed run."""

class NativeScenario:
    def to_json(self) -> str: ...
    def to_toml(self) -> str: ...
    def source(
        self,
    ) -> Tuple[Optional[str], str, str, List[Tuple[str, str]], List[str], List[Tuple[str, str]]]: ...
    def check_text(self) -> str: ...
    def check_json(self) -> str: ...
    def modes(
        self,
        count: int,
        shift: Optional[float],
        around: Optional[float],
        out: Optional[str],
        backend_name: str,
        overwrite: bool,
    ) -> Tuple[str, np.ndarray, List[str]]: ...
    def run(
        self,
        out: Optional[str],
        overwrite: bool,
        record_fields: bool,
        bar: bool,
        callback: Optional[object],
        threads: Optional[int],
        backend_name: str,
    ) -> NativeRun: ...

class NativeRun:
    def summary_json(self) -> str: ...
    def out(self) -> Optional[str]: ...
    def take_history(self) -> List[Tuple[str, np.ndarray]]: ...
    def mesh(
        self,
    ) -> Tuple[np.ndarray, List[Tuple[str, np.ndarray, np.ndarray]], List[Tuple[str, np.ndarray]]]: ...
    def fields(self) -> Optional[np.ndarray]: ...
    def displacement(self) -> np.ndarray: ...
    def cell_names(self) -> List[str]: ...
    def cell_data(self, name: str) -> Optional[np.ndarray]: ...

def scenario(
    source: str,
    kind: str,
    dir: Optional[str],
    variants: List[Tuple[str, str]],
    unsets: List[str],
    sets: List[Tuple[str, str]],
    ignore_memory: bool = False,
) -> NativeScenario: ...
def material(file: str | PathLike[str], out: str | PathLike[str]) -> int: ...
def study(
    kind: str,
    scenario: str,
    variants: List[Tuple[str, str]],
    unsets: List[str],
    sets: List[Tuple[str, str]],
    out: str,
    values: List[float],
    halvings: Optional[int],
    option: Optional[str],
    jobs: Optional[int],
    backend_name: str,
) -> Tuple[str, List[str]]: ...
