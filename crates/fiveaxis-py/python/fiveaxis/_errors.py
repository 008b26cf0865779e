"""The exceptions of fiveaxis: every failure is one of these (or a
TypeError for an argument of the wrong kind), never a crash."""

from __future__ import annotations

from typing import Any, Optional


class FiveaxisError(Exception):
    """Base class of the errors fiveaxis raises."""


class InputError(FiveaxisError, ValueError):
    """An input that cannot be used: a machine or offsets file (with the
    line, column and key at fault), a missing file, an array of the wrong
    shape or holding NaN, an unknown machine name, a bad option."""

    def __init__(
        self,
        message: str,
        file: Optional[str] = None,
        line: Optional[int] = None,
        column: Optional[int] = None,
        key: Optional[str] = None,
    ) -> None:
        self.message = message
        self.file = file
        self.line = line
        self.column = column
        self.key = key
        super().__init__(self._text())

    def _text(self) -> str:
        where = ""
        if self.file is not None:
            where = self.file
            if self.line is not None:
                where += f":{self.line}"
                if self.column is not None:
                    where += f":{self.column}"
            where += ": "
        key = f" (key `{self.key}`)" if self.key is not None else ""
        return f"{where}{self.message}{key}"

    def __str__(self) -> str:
        return self._text()


class Alarm(FiveaxisError):
    """The alarm that stopped a program, as the control shows it: `code`
    (e.g. ``OT0500``), the 1-based `line` of the failing block, the
    1-based `column` of the word at fault (None when no one word is),
    the `message`, the `program` it is in and the `text` of the line.

    `rows` holds the rows before the failing block (a `Rows`) when `run`
    raised it; None from `run_chunks` (those rows were yielded already).
    """

    def __init__(
        self,
        code: str,
        line: int,
        message: str,
        column: Optional[int] = None,
        program: Optional[str] = None,
        text: Optional[str] = None,
    ) -> None:
        self.code = code
        self.line = line
        self.column = column
        self.message = message
        self.program = program
        self.text = text
        self.rows: Any = None
        super().__init__(f"{code} line {line}: {message}")

    def __str__(self) -> str:
        return f"{self.code} line {self.line}: {self.message}"
