# Typing stubs of the fiveaxis package (the public API of __init__.py).
import os
from dataclasses import dataclass
from typing import Any, Dict, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from ._errors import Alarm as Alarm
from ._errors import FiveaxisError as FiveaxisError
from ._errors import InputError as InputError

__version__: str
MOTIONS: Tuple[str, ...]
DEFAULT_MACHINE: str
DEFAULT_MAX_BLOCKS: int
KINDS: Tuple[str, ...]

_Path = Union[str, os.PathLike[str]]
_Array = npt.ArrayLike
_MachineLike = Union["Machine", str, os.PathLike[str], None]
_OffsetsLike = Union["Offsets", Mapping[Any, Any], str, os.PathLike[str], None]
_Program = Union[str, os.PathLike[str], bytes, None]
_ProgramText = Union[str, bytes, os.PathLike[str]]
# Program numbers (9010, "O9010") for M98 / G65; SINUMERIK program names
# ("RLIMIT", "L100", "CYCLE1.SPF") and definition files ("GUD.DEF").
# Mapping's key is invariant: a dict of numbers, of names, or of both.
_Programs = Optional[
    Union[Mapping[int, _ProgramText], Mapping[str, _ProgramText], Mapping[Union[int, str], _ProgramText]]
]

def machines() -> List[str]: ...

@dataclass(frozen=True)
class Inverse:
    joints: npt.NDArray[np.float64]
    count: npt.NDArray[np.uint8]
    free_axis: npt.NDArray[np.int8]

class Machine:
    def __init__(self, name: str = ...) -> None: ...
    @classmethod
    def from_file(cls, path: _Path) -> Machine: ...
    @classmethod
    def from_toml(cls, text: str, file: str = ...) -> Machine: ...
    @property
    def name(self) -> str: ...
    @property
    def control(self) -> str: ...
    @property
    def machine_type(self) -> str: ...
    @property
    def axes(self) -> Tuple[str, ...]: ...
    @property
    def linear_axes(self) -> List[Dict[str, Any]]: ...
    @property
    def rotary_axes(self) -> List[Dict[str, Any]]: ...
    @property
    def limits(self) -> Dict[str, Optional[Tuple[float, float]]]: ...
    @property
    def parameters(self) -> Dict[str, Any]: ...
    @property
    def tool_direction(self) -> Tuple[float, float, float]: ...
    def to_toml(self) -> str: ...
    def forward(
        self, joints: _Array, tool_length: _Array = ...
    ) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    def inverse(
        self, tips: _Array, directions: _Array, tool_length: _Array = ..., held: Sequence[float] = ...
    ) -> Inverse: ...
    def choose(
        self, tips: _Array, directions: _Array, tool_length: _Array = ..., start: Sequence[float] = ...
    ) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.bool_]]: ...

class Offsets:
    def __init__(self, data: Optional[Mapping[Any, Any]] = ...) -> None: ...
    @classmethod
    def from_file(cls, path: _Path) -> Offsets: ...
    @classmethod
    def from_toml(cls, text: str, file: str = ...) -> Offsets: ...
    @property
    def tools(self) -> Dict[int, Dict[str, float]]: ...
    @property
    def work(self) -> Dict[str, Tuple[float, float, float]]: ...

class Rows:
    axis_names: Tuple[str, ...]
    line: npt.NDArray[np.uint32]
    s: npt.NDArray[np.float64]
    motion: npt.NDArray[np.uint8]
    axes: Dict[str, npt.NDArray[np.float64]]
    tip: npt.NDArray[np.float64]
    tool: npt.NDArray[np.float64]
    feed: npt.NDArray[np.float64]
    def __init__(self, columns: Mapping[str, Any], axis_names: Sequence[str]) -> None: ...
    def __len__(self) -> int: ...
    @property
    def names(self) -> Tuple[str, ...]: ...
    @property
    def joints(self) -> npt.NDArray[np.float64]: ...
    def motion_names(self) -> npt.NDArray[np.str_]: ...
    def __getitem__(self, name: str) -> npt.NDArray[Any]: ...
    def columns(self) -> Dict[str, npt.NDArray[Any]]: ...
    def structured(self) -> npt.NDArray[np.void]: ...
    @staticmethod
    def concatenate(parts: Sequence[Rows]) -> Rows: ...

def run(
    program: _Program = ...,
    machine: _MachineLike = ...,
    offsets: _OffsetsLike = ...,
    *,
    code: Optional[Union[str, bytes]] = ...,
    step: Optional[float] = ...,
    step_angle: float = ...,
    block_delete: bool = ...,
    optional_stop: bool = ...,
    max_blocks: int = ...,
    variables: Optional[Mapping[int, float]] = ...,
    programs: _Programs = ...,
) -> Rows: ...
def run_chunks(
    program: _Program = ...,
    machine: _MachineLike = ...,
    offsets: _OffsetsLike = ...,
    *,
    code: Optional[Union[str, bytes]] = ...,
    step: Optional[float] = ...,
    step_angle: float = ...,
    block_delete: bool = ...,
    optional_stop: bool = ...,
    max_blocks: int = ...,
    variables: Optional[Mapping[int, float]] = ...,
    programs: _Programs = ...,
    chunk_rows: int = ...,
) -> Iterator[Rows]: ...

@dataclass(frozen=True)
class Finding:
    kind: str
    severity: str
    line: int
    axis: Optional[str]
    value: Optional[float]
    message: str

@dataclass(frozen=True)
class AlarmInfo:
    code: str
    line: int
    message: str

@dataclass(frozen=True)
class AxisRange:
    name: str
    min: float
    max: float
    limits: Optional[Tuple[float, float]]

@dataclass(frozen=True)
class MachiningTime:
    programmed: float
    estimated: float

@dataclass(frozen=True)
class CheckReport:
    program: str
    machine: str
    ended: bool
    alarm: Optional[AlarmInfo]
    blocks: int
    time: MachiningTime
    feed_limited_seconds: float
    axes: List[AxisRange]
    findings: List[Finding]
    @property
    def errors(self) -> int: ...
    @property
    def warnings(self) -> int: ...
    @property
    def verdict(self) -> str: ...
    def counts(self) -> Dict[str, int]: ...
    def summary(self) -> str: ...

def check(
    program: _Program = ...,
    machine: _MachineLike = ...,
    offsets: _OffsetsLike = ...,
    *,
    code: Optional[Union[str, bytes]] = ...,
    block_delete: bool = ...,
    optional_stop: bool = ...,
    max_blocks: int = ...,
    variables: Optional[Mapping[int, float]] = ...,
    programs: _Programs = ...,
    keep_going: bool = ...,
) -> CheckReport: ...

@dataclass(frozen=True)
class PostResult:
    text: str
    deviation_tip: float
    deviation_angle: float
    source_blocks: int
    blocks: int
    unresolved: int
    tool_lengths: List[float]
    converted: bool
    cl_warnings: List[Tuple[int, str, str, int, bool]]

def apt_to_tcpc(text: str, name: str = ...) -> str: ...
def post(
    program: _Program = ...,
    machine: _MachineLike = ...,
    offsets: _OffsetsLike = ...,
    *,
    code: Optional[Union[str, bytes]] = ...,
    tolerance: float = ...,
    angle_tolerance: float = ...,
    apt: Optional[bool] = ...,
    programs: _Programs = ...,
    feed: Optional[str] = ...,
    retract: float = ...,
    from_machine: _MachineLike = ...,
    from_offsets: _OffsetsLike = ...,
    tool_length: Optional[float] = ...,
) -> PostResult: ...
