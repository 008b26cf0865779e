"""fiveaxis: a 5-axis CNC kernel for Python.

Runs the programs that real 5-axis machines run (FANUC format and the
controls that read it, SINUMERIK 840D programs, HEIDENHAIN TNC Klartext)
on a machine model, and
gives every machine axis, the tool tip and the tool direction as numpy
arrays; forward and inverse kinematics of whole arrays; the verification
report of ``fiveaxis check``; the machine-axis programs of ``fiveaxis
post``.

    >>> import fiveaxis as fx
    >>> rows = fx.run(code="G0 X10.\\nG1 X20. C90. F100.\\n")
    >>> rows["C"]
    array([ 0., 90.])

Units are millimetres and degrees throughout; tips and directions of
``run`` are in the part frame, those of the kinematics in the table
frame (machine coordinates with every rotary axis at 0).
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from typing import Any, Dict, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _native
from ._errors import Alarm, FiveaxisError, InputError

__all__ = [
    "Alarm",
    "AlarmInfo",
    "AxisRange",
    "CheckReport",
    "DEFAULT_MACHINE",
    "Finding",
    "FiveaxisError",
    "InputError",
    "Inverse",
    "MOTIONS",
    "Machine",
    "MachiningTime",
    "Offsets",
    "PostResult",
    "Rows",
    "apt_to_tcpc",
    "check",
    "machines",
    "post",
    "run",
    "run_chunks",
]

__version__: str = _native.VERSION

#: Names of the motion codes of ``Rows.motion`` (0 rapid, 1 linear, 2 cw, 3 ccw).
MOTIONS: Tuple[str, ...] = tuple(_native.MOTIONS)

#: The machine used when none is given.
DEFAULT_MACHINE: str = _native.default_machine()

#: The most lines a run reads before it stops with alarm FX0102.
DEFAULT_MAX_BLOCKS = 50_000_000

PathLike = Union[str, "os.PathLike[str]"]
ArrayLike = Any


def machines() -> List[str]:
    """The names of the built-in machines."""
    return list(_native.builtin_names())


# ----- arrays ---------------------------------------------------------------


def _array2(value: ArrayLike, name: str, cols: int) -> np.ndarray:
    """`value` as a C-contiguous float64 array of shape (n, cols); one row
    may be given as a flat sequence."""
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise InputError(f"{name} must be an array of numbers ({e})") from None
    if a.ndim == 1 and a.shape[0] == cols:
        a = a.reshape(1, cols)
    if a.ndim != 2 or a.shape[1] != cols:
        raise InputError(f"{name} must have shape (n, {cols}), not {a.shape}")
    return np.ascontiguousarray(a)


def _lengths(value: ArrayLike, n: int) -> np.ndarray:
    """A tool length per row: one number or n of them."""
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise InputError(f"tool_length must be a number or an array of numbers ({e})") from None
    if a.ndim == 0:
        a = np.full(n, float(a))
    if a.ndim != 1 or a.shape[0] != n:
        raise InputError(f"tool_length must be one number or have {n} entries, not shape {a.shape}")
    return np.ascontiguousarray(a)


def _pair(value: Sequence[float], name: str) -> Tuple[float, float]:
    try:
        a, b = (float(x) for x in value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be two angles in degrees") from None
    return a, b


# ----- machines and offsets -------------------------------------------------


@dataclass(frozen=True)
class Inverse:
    """Every inverse solution of each point.

    * ``joints``: machine positions, shape (n, 2, k); a point with fewer
      than two solutions has NaN rows in the unused places;
    * ``count``: how many solutions each point has (0, 1 or 2), shape (n,);
    * ``free_axis``: the rotary axis (0 or 1, machine order) that was free at
      a singular direction and kept its held angle, -1 where none, shape (n,).
    """

    joints: np.ndarray
    count: np.ndarray
    free_axis: np.ndarray


class Machine:
    """A machine: built in by name (``Machine("head-table-bc")``), from a
    machine file (``Machine.from_file(path)``) or from its TOML text
    (``Machine.from_toml(text)``). Immutable."""

    __slots__ = ("_native",)

    def __init__(self, name: str = DEFAULT_MACHINE) -> None:
        if not isinstance(name, str):
            raise TypeError(f"a machine name is a str, not {type(name).__name__}")
        self._native = _native.Machine.builtin(name)

    @classmethod
    def _wrap(cls, native: Any) -> "Machine":
        m = cls.__new__(cls)
        m._native = native
        return m

    @classmethod
    def from_file(cls, path: PathLike) -> "Machine":
        """A machine from a machine file (docs/machine-file.md)."""
        return cls._wrap(_native.Machine.from_file(os.fspath(path)))

    @classmethod
    def from_toml(cls, text: str, file: str = "<string>") -> "Machine":
        """A machine from the text of a machine file; `file` names it in errors."""
        if not isinstance(text, str):
            raise TypeError(f"machine TOML is a str, not {type(text).__name__}")
        return cls._wrap(_native.Machine.from_toml(text, file))

    @property
    def name(self) -> str:
        return self._native.name

    @property
    def control(self) -> str:
        """The control family (``fanuc30i``, ``fanuc16``, ``mitsubishi``, ``mazak``, ``haas``)."""
        return self._native.control

    @property
    def machine_type(self) -> str:
        """``none``, ``head``, ``table`` or ``mixed`` (FANUC parameter 19680)."""
        return self._native.machine_type

    @property
    def axes(self) -> Tuple[str, ...]:
        """Axis names in machine order: the columns of positions."""
        return tuple(self._native.axes)

    @property
    def linear_axes(self) -> List[Dict[str, Any]]:
        """Linear axes: ``name``, ``min``, ``max`` (mm) and ``dynamics``."""
        return self._native.linear_axes

    @property
    def rotary_axes(self) -> List[Dict[str, Any]]:
        """Rotary axes bed outwards: ``name``, ``on`` (head/table), ``axis``,
        ``center``, ``limits`` (None: none), ``rollover``, ``dynamics``."""
        return self._native.rotary_axes

    @property
    def limits(self) -> Dict[str, Optional[Tuple[float, float]]]:
        """Soft limits by axis name (None for an axis without)."""
        out: Dict[str, Optional[Tuple[float, float]]] = {}
        for a in self.linear_axes:
            out[a["name"]] = (a["min"], a["max"])
        for a in self.rotary_axes:
            out[a["name"]] = None if a["rollover"] else a["limits"]
        return out

    @property
    def parameters(self) -> Dict[str, Any]:
        """Control parameters by their machine-file names."""
        return self._native.parameters

    @property
    def tool_direction(self) -> Tuple[float, float, float]:
        return self._native.tool_direction

    def to_toml(self) -> str:
        """The machine as a machine file."""
        return self._native.to_toml()

    def __repr__(self) -> str:
        return f"Machine({self.name!r}, axes={''.join(self.axes)!r})"

    def forward(self, joints: ArrayLike, tool_length: ArrayLike = 0.0) -> Tuple[np.ndarray, np.ndarray]:
        """Forward kinematics of machine positions (n, k) with tool lengths
        (one or n): tool tips and unit tool directions (n, 3), table frame."""
        j = _array2(joints, "joints", len(self.axes))
        return _native.forward(self._native, j, _lengths(tool_length, j.shape[0]))

    def inverse(
        self,
        tips: ArrayLike,
        directions: ArrayLike,
        tool_length: ArrayLike = 0.0,
        held: Sequence[float] = (0.0, 0.0),
    ) -> Inverse:
        """Every machine position putting the tool tip of `tool_length` on
        each tip (n, 3) along each direction (n, 3, any length), table frame.
        Rotary angles in (-180, 180]; at a singular direction the free axis
        keeps its angle from `held`."""
        t = _array2(tips, "tips", 3)
        d = _array2(directions, "directions", 3)
        joints, count, free = _native.inverse(
            self._native, t, d, _lengths(tool_length, t.shape[0]), _pair(held, "held")
        )
        return Inverse(joints, count, free)

    def choose(
        self,
        tips: ArrayLike,
        directions: ArrayLike,
        tool_length: ArrayLike = 0.0,
        start: Sequence[float] = (0.0, 0.0),
    ) -> Tuple[np.ndarray, np.ndarray]:
        """The control's choice along a path: for each point in order, the
        machine position TCPC would command (the machine's rotary choice
        from where the previous point left the rotary axes, the first from
        `start`, repeats inside the soft limits). Returns positions (n, k)
        and a bool array `reached`; an unreachable point is NaN and leaves
        the axes where they were. Needs two rotary axes."""
        t = _array2(tips, "tips", 3)
        d = _array2(directions, "directions", 3)
        return _native.inverse_choice(
            self._native, t, d, _lengths(tool_length, t.shape[0]), _pair(start, "start")
        )


class Offsets:
    """Offset memory: tool lengths and radii, work offsets, setup-error data
    sets. ``Offsets(dict)`` takes the shape of an offsets file::

        Offsets({"tools": {1: {"length": 100.0, "radius": 5.0}},
                 "work": {"G54": [0.0, 0.0, 50.0]}})

    ``Offsets.from_file(path)`` and ``Offsets.from_toml(text)`` read one."""

    __slots__ = ("_native",)

    def __init__(self, data: Optional[Mapping[Any, Any]] = None) -> None:
        if data is None:
            self._native = _native.Offsets()
        elif isinstance(data, Mapping):
            self._native = _native.Offsets.from_dict(dict(data))
        else:
            raise TypeError(f"offsets are a dict, not {type(data).__name__}")

    @classmethod
    def _wrap(cls, native: Any) -> "Offsets":
        o = cls.__new__(cls)
        o._native = native
        return o

    @classmethod
    def from_file(cls, path: PathLike) -> "Offsets":
        return cls._wrap(_native.Offsets.from_file(os.fspath(path)))

    @classmethod
    def from_toml(cls, text: str, file: str = "<string>") -> "Offsets":
        if not isinstance(text, str):
            raise TypeError(f"offsets TOML is a str, not {type(text).__name__}")
        return cls._wrap(_native.Offsets.from_toml(text, file))

    @property
    def tools(self) -> Dict[int, Dict[str, float]]:
        return self._native.tools

    @property
    def work(self) -> Dict[str, Tuple[float, float, float]]:
        return self._native.work

    def __repr__(self) -> str:
        return f"Offsets(tools={self.tools!r})"


MachineLike = Union[Machine, str, "os.PathLike[str]", None]
OffsetsLike = Union[Offsets, Mapping[Any, Any], str, "os.PathLike[str]", None]


def _machine(machine: MachineLike) -> Any:
    """A built-in name, a machine file, or a Machine (as the CLI's --machine)."""
    if machine is None:
        return _native.Machine.builtin(DEFAULT_MACHINE)
    if isinstance(machine, Machine):
        return machine._native
    if isinstance(machine, (str, os.PathLike)):
        spec = os.fspath(machine)
        if isinstance(machine, str) and spec in _native.builtin_names():
            return _native.Machine.builtin(spec)
        if os.path.exists(spec):
            return _native.Machine.from_file(spec)
        raise InputError(
            f"`{spec}` is neither a built-in machine nor a machine file;"
            f" built-in machines: {', '.join(_native.builtin_names())}"
        )
    raise TypeError(f"machine must be a Machine, a name or a path, not {type(machine).__name__}")


def _offsets(offsets: OffsetsLike) -> Any:
    if offsets is None:
        return _native.Offsets()
    if isinstance(offsets, Offsets):
        return offsets._native
    if isinstance(offsets, Mapping):
        return _native.Offsets.from_dict(dict(offsets))
    if isinstance(offsets, (str, os.PathLike)):
        return _native.Offsets.from_file(os.fspath(offsets))
    raise TypeError(f"offsets must be Offsets, a dict or a path, not {type(offsets).__name__}")


def _program(program: Any, code: Any) -> Tuple[Optional[str], Optional[bytes]]:
    """The program as (path, None) or (None, text bytes)."""
    if program is not None and code is not None:
        raise InputError("give the program as a path or as code=..., not both")
    if isinstance(program, (bytes, bytearray)):
        return None, bytes(program)
    if program is not None:
        if not isinstance(program, (str, os.PathLike)):
            raise TypeError(f"program is a path, not {type(program).__name__}")
        return os.fspath(program), None
    if code is None:
        raise InputError("give the program as a path or as code=...")
    if isinstance(code, str):
        return None, code.encode("utf-8")
    if isinstance(code, (bytes, bytearray)):
        return None, bytes(code)
    raise TypeError(f"code is str or bytes, not {type(code).__name__}")


def _variables(variables: Optional[Mapping[int, float]]) -> Optional[List[Tuple[int, float]]]:
    if variables is None:
        return None
    out = []
    for k, v in variables.items():
        key = str(k).lstrip("#")
        if not key.isdigit():
            raise InputError(f"variable `{k}`: a variable number, as 500 or '#500'")
        try:
            out.append((int(key), float(v)))
        except (TypeError, ValueError):
            raise InputError(f"variable #{key}: {v!r} is not a number") from None
    return out


_ProgramText = Union[str, bytes, "os.PathLike[str]"]
ProgramsLike = Optional[
    Union[Mapping[int, _ProgramText], Mapping[str, _ProgramText], Mapping[Union[int, str], _ProgramText]]
]

#: A program name as ``programs=`` takes it: letters, digits and ``_``,
#: with ``.SPF``, ``.MPF`` or ``.DEF`` (a SINUMERIK definition file) or
#: ``.H`` (a HEIDENHAIN program) after it.
_PROGRAM_NAME = re.compile(r"[A-Za-z0-9_]+(\.(spf|mpf|def|h))?", re.IGNORECASE)


def _program_key(k: Any) -> Union[int, str]:
    """A key of ``programs=``: a program number (``9010``, ``"O9010"``) or a
    program name (SINUMERIK ``"RLIMIT"``, ``"L100"``, ``"GUD.DEF"``;
    HEIDENHAIN ``"SUB1.h"``)."""
    if isinstance(k, str) and not k.upper().lstrip("O").isdigit():
        if not _PROGRAM_NAME.fullmatch(k):
            raise InputError(
                f"program `{k}`: a program number, as 9010 or 'O9010', or a program"
                " name, as 'RLIMIT', 'L100', 'CYCLE1.SPF', 'GUD.DEF' or 'SUB1.h'"
            )
        return k
    key = str(k).upper().lstrip("O")
    if not key.isdigit() or len(key) > 8:
        raise InputError(f"program `{k}`: a program number, as 9010 or 'O9010'")
    return int(key)


def _programs(programs: ProgramsLike) -> Optional[List[Tuple[Union[int, str], bytes]]]:
    """The control's program memory: program texts (or files) by number,
    and SINUMERIK programs and definition files by name."""
    if programs is None:
        return None
    if not isinstance(programs, Mapping):
        raise TypeError(f"programs are a dict of number or name: text or path, not {type(programs).__name__}")
    out: List[Tuple[Union[int, str], bytes]] = []
    for k, v in programs.items():
        key = _program_key(k)
        if isinstance(v, str):
            text = v.encode("utf-8")
        elif isinstance(v, (bytes, bytearray)):
            text = bytes(v)
        elif isinstance(v, os.PathLike):
            try:
                with open(v, "rb") as f:
                    text = f.read()
            except OSError as e:
                raise InputError(str(e.strerror or e), file=os.fspath(v)) from None
        else:
            raise TypeError(f"program {k}: text, bytes or a path, not {type(v).__name__}")
        out.append((key, text))
    return out


# ----- run ------------------------------------------------------------------


class Rows:
    """The rows of a run by column, as ``fiveaxis run`` writes them in CSV:

    * ``line`` (uint32), ``s`` (float64), ``motion`` (uint8 codes into
      ``MOTIONS``);
    * one float64 column per machine axis (``rows["X"]``; rollover axes in
      [0, 360)), and ``joints`` (n, k) for all of them;
    * ``tip`` and ``tool`` (n, 3): tool tip and unit tool direction in the
      part frame (``rows["tip_x"]`` … ``rows["tool_k"]``);
    * ``feed`` (float64, mm/min; NaN for rapid moves).
    """

    __slots__ = ("axis_names", "line", "s", "motion", "axes", "tip", "tool", "feed")

    def __init__(self, columns: Mapping[str, Any], axis_names: Sequence[str]) -> None:
        self.axis_names: Tuple[str, ...] = tuple(axis_names)
        self.line: np.ndarray = columns["line"]
        self.s: np.ndarray = columns["s"]
        self.motion: np.ndarray = columns["motion"]
        self.axes: Dict[str, np.ndarray] = dict(zip(self.axis_names, columns["axes"]))
        self.tip: np.ndarray = columns["tip"]
        self.tool: np.ndarray = columns["tool"]
        self.feed: np.ndarray = columns["feed"]

    def __len__(self) -> int:
        return int(self.line.shape[0])

    def __repr__(self) -> str:
        return f"Rows({len(self)} rows, axes {''.join(self.axis_names)})"

    @property
    def names(self) -> Tuple[str, ...]:
        """Column names in the CSV's order."""
        return (
            ("line", "s", "motion")
            + self.axis_names
            + ("tip_x", "tip_y", "tip_z", "tool_i", "tool_j", "tool_k", "feed")
        )

    @property
    def joints(self) -> np.ndarray:
        """Machine positions (n, k), axes in machine order."""
        if not self.axis_names:
            return np.zeros((len(self), 0))
        return np.column_stack([self.axes[a] for a in self.axis_names])

    def motion_names(self) -> np.ndarray:
        """The motion of each row as a string array."""
        return np.asarray(MOTIONS)[self.motion]

    def __getitem__(self, name: str) -> np.ndarray:
        pose = {"tip_x": (self.tip, 0), "tip_y": (self.tip, 1), "tip_z": (self.tip, 2),
                "tool_i": (self.tool, 0), "tool_j": (self.tool, 1), "tool_k": (self.tool, 2)}
        if name in self.axes:
            return self.axes[name]
        if name in pose:
            a, i = pose[name]
            return a[:, i]
        if name in ("line", "s", "motion", "feed"):
            return getattr(self, name)
        raise KeyError(name)

    def columns(self) -> Dict[str, np.ndarray]:
        """Every column by its CSV name, in the CSV's order."""
        return {name: self[name] for name in self.names}

    def structured(self) -> np.ndarray:
        """The rows as one numpy structured array, a field per CSV column
        (``motion`` as its code)."""
        types = {"line": np.uint32, "motion": np.uint8}
        dtype = [(name, types.get(name, np.float64)) for name in self.names]
        out = np.empty(len(self), dtype=dtype)
        for name in self.names:
            out[name] = self[name]
        return out

    @staticmethod
    def concatenate(parts: Sequence["Rows"]) -> "Rows":
        """Chunks of one run joined into one."""
        if not parts:
            raise InputError("nothing to concatenate")
        names = parts[0].axis_names
        cols = {
            "line": np.concatenate([p.line for p in parts]),
            "s": np.concatenate([p.s for p in parts]),
            "motion": np.concatenate([p.motion for p in parts]),
            "axes": [np.concatenate([p.axes[a] for p in parts]) for a in names],
            "tip": np.concatenate([p.tip for p in parts]),
            "tool": np.concatenate([p.tool for p in parts]),
            "feed": np.concatenate([p.feed for p in parts]),
        }
        return Rows(cols, names)


def run(
    program: Optional[Union[PathLike, bytes]] = None,
    machine: MachineLike = None,
    offsets: OffsetsLike = None,
    *,
    code: Optional[Union[str, bytes]] = None,
    step: Optional[float] = None,
    step_angle: float = 1.0,
    block_delete: bool = False,
    optional_stop: bool = False,
    max_blocks: int = DEFAULT_MAX_BLOCKS,
    variables: Optional[Mapping[int, float]] = None,
    programs: ProgramsLike = None,
) -> Rows:
    """Runs a program (a file path, or its text as ``code=``) on a machine
    (built-in name, machine file or ``Machine``; default ``trunnion-ac``)
    with offsets (``Offsets``, dict or offsets file) and returns every row
    as numpy columns, as ``fiveaxis run`` (``--step``, ``--step-angle``,
    ``--block-delete``, ``--optional-stop``, ``--max-blocks``, variables
    ``{500: 1.25}``; `programs`: the control's program memory that ``M98`` /
    ``G65`` call, ``{9010: text or path}``, SINUMERIK programs by name,
    ``{"RLIMIT": ..., "GUD.DEF": ...}``, and HEIDENHAIN programs that
    ``CALL PGM`` runs, ``{"SUB1.h": ...}``, as ``--programs``).
    SINUMERIK text (a path ending ``.mpf`` / ``.spf``, or a text starting
    with a transfer header ``%_N_``) runs on the machine read as a
    SINUMERIK, as on the command line.

    An alarm raises ``Alarm`` with ``code``, ``line``, ``column``,
    ``message``, and ``rows``: the rows before the failing block."""
    path, text = _program(program, code)
    m = _machine(machine)
    try:
        cols = _native.run(
            m, _offsets(offsets), path, text,
            step=step, step_angle=float(step_angle), block_delete=bool(block_delete),
            optional_stop=bool(optional_stop), max_blocks=_count(max_blocks, "max_blocks"),
            variables=_variables(variables), programs=_programs(programs),
        )
    except Alarm as alarm:
        if isinstance(alarm.rows, dict):
            alarm.rows = Rows(alarm.rows, m.axes)
        raise
    return Rows(cols, m.axes)


def _count(value: int, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise InputError(f"{name} must be a whole number of at least 1, not {value!r}")
    return int(min(value, 2**63 - 1))


def run_chunks(
    program: Optional[Union[PathLike, bytes]] = None,
    machine: MachineLike = None,
    offsets: OffsetsLike = None,
    *,
    code: Optional[Union[str, bytes]] = None,
    step: Optional[float] = None,
    step_angle: float = 1.0,
    block_delete: bool = False,
    optional_stop: bool = False,
    max_blocks: int = DEFAULT_MAX_BLOCKS,
    variables: Optional[Mapping[int, float]] = None,
    programs: ProgramsLike = None,
    chunk_rows: int = 65536,
) -> Iterator[Rows]:
    """``run`` for programs too large for memory: yields ``Rows`` of about
    `chunk_rows` rows each while the program runs in a thread of its own
    (at most two chunks ahead). An alarm is raised after the rows before it
    have been yielded."""
    path, text = _program(program, code)
    m = _machine(machine)
    stream = _native.run_stream(
        m, _offsets(offsets), path, text,
        step=step, step_angle=float(step_angle), block_delete=bool(block_delete),
        optional_stop=bool(optional_stop), max_blocks=_count(max_blocks, "max_blocks"),
        variables=_variables(variables), programs=_programs(programs),
        chunk_rows=_count(chunk_rows, "chunk_rows"),
    )
    names = m.axes

    def chunks() -> Iterator[Rows]:
        for cols in stream:
            yield Rows(cols, names)

    return chunks()


# ----- check ----------------------------------------------------------------


@dataclass(frozen=True)
class Finding:
    """One finding of ``check`` (the check contract's keys)."""

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
    """The range an axis covered and its soft limits (None: none)."""

    name: str
    min: float
    max: float
    limits: Optional[Tuple[float, float]]


@dataclass(frozen=True)
class MachiningTime:
    """Seconds: ``programmed`` (path over feed, rapids at their rates) and
    ``estimated`` (the velocity planner over the machine axes)."""

    programmed: float
    estimated: float


KINDS = ("alarm", "overtravel", "singular_passage", "rotary_flip", "feed_limited", "chord_error")


@dataclass(frozen=True)
class CheckReport:
    """What ``fiveaxis check`` reports of one program."""

    program: str
    machine: str
    ended: bool
    alarm: Optional[AlarmInfo]
    blocks: int
    time: MachiningTime
    feed_limited_seconds: float
    axes: List[AxisRange]
    findings: List[Finding] = field(default_factory=list)

    @property
    def errors(self) -> int:
        return sum(1 for f in self.findings if f.severity == "error")

    @property
    def warnings(self) -> int:
        return sum(1 for f in self.findings if f.severity == "warning")

    @property
    def verdict(self) -> str:
        """``FAIL`` with errors, ``WARN`` with warnings, else ``PASS``."""
        return "FAIL" if self.errors else "WARN" if self.warnings else "PASS"

    def counts(self) -> Dict[str, int]:
        """Findings by kind, every kind listed."""
        out = {k: 0 for k in KINDS}
        for f in self.findings:
            out[f.kind] = out.get(f.kind, 0) + 1
        return out

    def summary(self) -> str:
        """The report's first line, as the text report has it."""
        return (
            f"{self.verdict}  {self.program} on {self.machine}: "
            f"{self.errors} errors, {self.warnings} warnings"
        )


def check(
    program: Optional[Union[PathLike, bytes]] = None,
    machine: MachineLike = None,
    offsets: OffsetsLike = None,
    *,
    code: Optional[Union[str, bytes]] = None,
    block_delete: bool = False,
    optional_stop: bool = False,
    max_blocks: int = DEFAULT_MAX_BLOCKS,
    variables: Optional[Mapping[int, float]] = None,
    programs: ProgramsLike = None,
    keep_going: bool = False,
) -> CheckReport:
    """Checks a program as ``fiveaxis check`` does: the soft limits lifted,
    every over-travel, singular passage, rotary flip, feed limit and chord
    error found, the machining time. An alarm is a finding (and
    ``report.alarm``), not an exception. ``keep_going``: as ``check
    --keep-going``, an alarm after which the control's state is defined is
    a finding and the check goes on from the next line (``report.alarm``
    is then the first)."""
    path, text = _program(program, code)
    d = _native.check(
        _machine(machine), _offsets(offsets), path, text,
        block_delete=bool(block_delete), optional_stop=bool(optional_stop),
        max_blocks=_count(max_blocks, "max_blocks"), variables=_variables(variables),
        programs=_programs(programs), keep_going=bool(keep_going),
    )
    alarm = AlarmInfo(**d["alarm"]) if d["alarm"] is not None else None
    return CheckReport(
        program=d["program"],
        machine=d["machine"],
        ended=d["ended"],
        alarm=alarm,
        blocks=d["blocks"],
        time=MachiningTime(**d["time"]),
        feed_limited_seconds=d["feed_limited_seconds"],
        axes=[AxisRange(n, lo, hi, lim) for (n, lo, hi, lim) in d["axes"]],
        findings=[Finding(*f) for f in d["findings"]],
    )


# ----- post -----------------------------------------------------------------


@dataclass(frozen=True)
class PostResult:
    """A machine-axis program of ``post``: its ``text``, the largest
    deviation of its tool tip (mm) and direction (degrees) from the
    programmed path, the source's cutting blocks, the output's blocks,
    pieces that could not meet the tolerance, and the tool lengths it is
    for. ``converted`` is ``False`` when the program had nothing to
    convert (no TCPC, no tilted working plane, no CL data, the same
    machine): then ``text`` is the program unchanged. ``cl_warnings``: for
    CL input, the major words not carried out, each ``(line, word,
    message, count, note)`` (``note``: a known word skipped on purpose, else
    a word the reader does not know), as ``fiveaxis post`` prints them."""

    text: str
    deviation_tip: float
    deviation_angle: float
    source_blocks: int
    blocks: int
    unresolved: int
    tool_lengths: List[float]
    converted: bool = True
    cl_warnings: List[Tuple[int, str, str, int, bool]] = field(default_factory=list)


def apt_to_tcpc(text: str, name: str = "<string>") -> str:
    """APT / CL data (``GOTO/x,y,z,i,j,k``, ``FEDRAT``, ``CIRCLE``, ...) as
    a TCPC program (``G43.5`` with tool vectors)."""
    if not isinstance(text, str):
        raise TypeError(f"APT text is a str, not {type(text).__name__}")
    return _native.apt_to_tcpc(text, name)


def post(
    program: Optional[Union[PathLike, bytes]] = None,
    machine: MachineLike = None,
    offsets: OffsetsLike = None,
    *,
    code: Optional[Union[str, bytes]] = None,
    tolerance: float = 0.01,
    angle_tolerance: float = 0.1,
    apt: Optional[bool] = None,
    programs: ProgramsLike = None,
    feed: Optional[str] = None,
    retract: float = 5.0,
    from_machine: MachineLike = None,
    from_offsets: OffsetsLike = None,
    tool_length: Optional[float] = None,
) -> PostResult:
    """Converts a program that uses TCPC (G43.4 / G43.5) or the tilted
    working plane into a machine-axis program for the same machine without
    those options, within `tolerance` (mm) and `angle_tolerance` (degrees),
    as ``fiveaxis post``. APT / CL input (``apt=True``, default for files
    named ``.apt``, ``.cl``, ``.cls``, ``.ncl``, ``.aptsource``) is
    converted first. ``feed``:
    ``"inverse-time"`` (G93; the default), ``"dpm"`` (the default for a
    HEIDENHAIN machine, which has no inverse time) or ``"programmed"``;
    ``retract``:
    mm along the tool axis at a flip; ``from_machine`` (with
    ``from_offsets``, ``tool_length``): a machine-axis program written for
    that machine, retargeted to ``machine``, as ``--from-machine``.
    ``tool_length`` (mm) is also the length of every tool the offsets give
    none: a machine-axis program is right for one tool length only, and
    without a length from ``offsets`` or ``tool_length`` ``post`` raises
    ``InputError``, as ``fiveaxis post`` stops. A program with nothing to
    convert comes back unchanged (``converted`` ``False``). An alarm in
    the source raises ``Alarm``."""
    path, text = _program(program, code)
    if apt is None:
        apt = path is not None and _native.is_cl_file_name(str(path))
    d = _native.post(
        _machine(machine), _offsets(offsets), path, text,
        tolerance=float(tolerance), angle_tolerance=float(angle_tolerance), apt=bool(apt),
        programs=_programs(programs), feed=None if feed is None else str(feed), retract=float(retract),
        from_machine=None if from_machine is None else _machine(from_machine),
        from_offsets=None if from_offsets is None else _offsets(from_offsets),
        tool_length=None if tool_length is None else float(tool_length),
    )
    return PostResult(**d)
