"""Errors that are the user's to fix (bad configuration, bad readings, missing files).

The command line turns a :class:`DceeInputError` into a one-line message and exit code 2;
anything else is a bug and keeps its traceback.
"""

from __future__ import annotations


class DceeInputError(ValueError):
    """Invalid user input. ``field`` names what was wrong; the message says what is allowed."""

    def __init__(self, field: str, message: str) -> None:
        self.field = field
        self.message = message
        super().__init__(f"{field}: {message}")
