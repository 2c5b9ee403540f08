"""The one error type for bad input, and messages of bounded length.

:class:`InputError` is what every reader, the scenario loader and every command raise for
anything wrong with what the user gave — a file, a value, an option. It is a
:class:`ValueError`, so code that catches ``ValueError`` keeps working; the command line
turns it into one line on stderr and exit status 2. Its message names the file (when there
is one) and what was expected, and is never longer than :data:`MAX_MESSAGE` characters:
whatever the file holds (a 100 000-character header cell, a nested structure) is shown
elided (:func:`shown`), and the whole message is cut in the middle if it still exceeds the
bound (:func:`bounded`).
"""

from __future__ import annotations

__all__ = ["MAX_MESSAGE", "InputError", "bounded", "shown"]

#: Longest message an :class:`InputError` carries (characters).
MAX_MESSAGE = 500
_MARK = " … "


def bounded(text: str, limit: int = MAX_MESSAGE) -> str:
    """``text`` cut in the middle to at most ``limit`` characters (its start, which names
    the file, and its end, which says what was expected, are kept)."""
    if len(text) <= limit:
        return text
    keep = limit - len(_MARK)
    head = (2 * keep) // 3
    return text[:head] + _MARK + text[len(text) - (keep - head):]


def shown(value: object, limit: int = 60) -> str:
    """``repr(value)`` elided to at most ``limit`` characters, for quoting user content."""
    return bounded(repr(value), limit)


class InputError(ValueError):
    """Something is wrong with what the user gave (a file, a value, an option).

    The message should name the file and say what was expected; it is bounded to
    :data:`MAX_MESSAGE` characters (:func:`bounded`).
    """

    def __init__(self, message: object) -> None:
        super().__init__(bounded(str(message)))
