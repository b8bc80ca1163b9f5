"""Status enumerations: one per solver layer, each code with its message.

A status is a ``str`` enum: it compares equal to its value (``"periodic"``,
``"complete"``, ...), which is what files, tables and JSON carry, and every
member has a one-line ``message`` saying what it means for the user. Each
layer defines its own enumeration by subclassing :class:`Status`::

    class BranchStatus(Status):
        COMPLETE = "complete", "the branch covers the requested range", True
        FAILED = "failed", "the corrector failed: the branch stops short"

The optional third element marks the members that deliver what was asked
(``ok``; default False).
"""

from __future__ import annotations

import enum

__all__ = ["Status"]


class Status(str, enum.Enum):
    """Base of the status enumerations (value, message)."""

    def __new__(cls, value: str, message: str = "", ok: bool = False):
        obj = str.__new__(cls, value)
        obj._value_ = value
        obj._message = message
        obj._ok = bool(ok)
        return obj

    @property
    def message(self) -> str:
        """What the status means, in one line."""
        return self._message

    @property
    def ok(self) -> bool:
        """True when the result is what was asked for."""
        return self._ok

    @property
    def code(self) -> int:
        """Position of the member in its enumeration (an int8-friendly code)."""
        return list(type(self)).index(self)

    @classmethod
    def from_code(cls, code: int):
        """The member at position ``code``."""
        return list(cls)[int(code)]

    def __str__(self) -> str:
        return self.value

    def __format__(self, spec: str) -> str:
        return format(self.value, spec)
