"""Checks of the numbers, flags and arrays a user hands to `dirac`.

Each ``validate_*`` helper returns the cleaned value (a ``float``, ``int``, ``bool`` or
float64 array) or raises :class:`dirac.errors.InputError` with one line that names the
input and says what to give instead. ``name`` is how the message names the input, with
any location in front of it, e.g. ``"scene.toml: [run] dt"``.

``True`` and ``False`` are never numbers here: Python and numpy would silently read them
as 1 and 0, so a scene with ``M = [false, 0.2, 0.1]`` would run a body nobody asked for.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Iterable, Sequence
from typing import TypeGuard

import numpy as np

from dirac.errors import InputError

__all__ = [
    "is_real_number",
    "contains_boolean",
    "validate_finite",
    "validate_positive",
    "validate_non_negative",
    "validate_integer",
    "validate_boolean",
    "validate_array",
    "did_you_mean",
    "unknown_name_error",
    "check_known_keys",
]


def contains_boolean(value: object) -> bool:
    """Whether ``value`` is, or (as a list, tuple or array) contains, ``True`` or ``False``."""
    if isinstance(value, (bool, np.bool_)):
        return True
    if isinstance(value, np.ndarray):
        return value.dtype == bool or (value.dtype == object and any(contains_boolean(v) for v in value.flat))
    if isinstance(value, (list, tuple)):
        return any(contains_boolean(v) for v in value)
    return False


def is_real_number(value: object) -> TypeGuard[float]:
    """Whether ``value`` is a Python or numpy integer or float (never ``True``/``False``)."""
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))


def _is_integer(value: object) -> TypeGuard[int]:
    """A Python or numpy integer, not a boolean."""
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def _shown(value: object) -> str:
    """``repr`` of an input on one line (an array as the nested list of its entries)."""
    return repr(value.tolist()) if isinstance(value, np.ndarray) else repr(value)


def _with_hint(message: str, hint: str) -> str:
    return f"{message} ({hint})" if hint else message


def validate_finite(value: object, name: str, hint: str = "") -> float:
    """A finite real number.

    Parameters
    ----------
    value : object
        The input.
    name : str
        How the message names the input.
    hint : str
        What the number means, added to the message in parentheses.

    Returns
    -------
    float

    Raises
    ------
    InputError
        ``"<name> = <value> must be a finite number"`` for booleans, non-numbers, NaN and
        infinities.
    """
    if not is_real_number(value) or not math.isfinite(value):
        raise InputError(_with_hint(f"{name} = {value!r} must be a finite number", hint))
    return float(value)


def validate_positive(value: object, name: str, hint: str = "") -> float:
    """A finite real number ``> 0`` (a time, a step, a tolerance, a radius).

    Returns
    -------
    float

    Raises
    ------
    InputError
        ``"<name> = <value> must be a finite number > 0"``.
    """
    if not is_real_number(value) or not math.isfinite(value) or value <= 0:
        raise InputError(_with_hint(f"{name} = {value!r} must be a finite number > 0", hint))
    return float(value)


def validate_non_negative(value: object, name: str, hint: str = "") -> float:
    """A finite real number ``>= 0`` (a weight, a spread).

    Returns
    -------
    float

    Raises
    ------
    InputError
        ``"<name> = <value> must be a finite number >= 0"``.
    """
    if not is_real_number(value) or not math.isfinite(value) or value < 0:
        raise InputError(_with_hint(f"{name} = {value!r} must be a finite number >= 0", hint))
    return float(value)


def validate_integer(value: object, name: str, minimum: int = 1, maximum: int | None = None, hint: str = "") -> int:
    """An integer in ``[minimum, maximum]`` (a count, a number of samples or iterations).

    A float such as ``2.0`` is refused: a count written with a decimal point is a typo
    more often than not.

    Parameters
    ----------
    value : object
        The input.
    name : str
        How the message names the input.
    minimum : int
        Smallest value accepted (1: a positive integer).
    maximum : int, optional
        Largest value accepted; none by default.
    hint : str
        What the number means, added to the message in parentheses.

    Returns
    -------
    int

    Raises
    ------
    InputError
        ``"<name> = <value> must be an integer >= <minimum>"`` (or ``in [minimum, maximum]``).
    """
    if not _is_integer(value) or value < minimum or (maximum is not None and value > maximum):
        bound = f">= {minimum}" if maximum is None else f"in [{minimum}, {maximum}]"
        raise InputError(_with_hint(f"{name} = {value!r} must be an integer {bound}", hint))
    return int(value)


def validate_boolean(value: object, name: str) -> bool:
    """``True`` or ``False`` (not 0, 1 or a string).

    Raises
    ------
    InputError
        ``"<name> must be true or false"``.
    """
    if not isinstance(value, (bool, np.bool_)):
        raise InputError(f"{name} must be true or false")
    return bool(value)


def validate_array(value: object, name: str, shape: Sequence[int] | None = None, finite: bool = True) -> np.ndarray:
    """An array of real numbers: a number, list or array read as float64.

    Parameters
    ----------
    value : object
        The input; booleans anywhere in it are refused.
    name : str
        How the message names the input, e.g. ``"inertia"`` or ``"scene.toml: [initial] M"``.
    shape : sequence of int, optional
        The required shape; any shape when omitted.
    finite : bool
        Whether NaN and infinities are refused.

    Returns
    -------
    numpy.ndarray
        A new float64 array.

    Raises
    ------
    InputError
        Booleans (``contains true/false``), entries that are not numbers (``is not
        numeric``), another shape (``has shape``), NaN or infinities (``has non-finite
        entries``).
    """
    wanted = f"{tuple(shape)} real numbers" if shape is not None else "real numbers"
    if contains_boolean(value):
        raise InputError(f"{name} = {_shown(value)} contains true/false; give {wanted}")
    try:
        array = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} = {_shown(value)} is not numeric; give {wanted}") from exc
    if shape is not None and array.shape != tuple(shape):
        raise InputError(f"{name} has shape {array.shape}; it must have shape {tuple(shape)}")
    if finite and not np.all(np.isfinite(array)):
        raise InputError(f"{name} = {array.tolist()} has non-finite entries; give finite numbers")
    return array


def did_you_mean(name: str, known: Iterable[str]) -> str:
    """`` (did you mean 'a' or 'b'?)`` with the names of ``known`` closest to ``name``, or
    ``""`` when none is close.

    Names equal to ``name`` but for upper and lower case come first (``L`` -> ``l``), then
    the closest by :func:`difflib.get_close_matches`; ``name`` itself is never suggested.
    """
    name = str(name)
    names = sorted(set(map(str, known)) - {name})
    same_letters = [k for k in names if k.lower() == name.lower()]
    close = same_letters + [k for k in difflib.get_close_matches(name, names, n=3) if k not in same_letters]
    close = close[:3]
    if not close:
        return ""
    return f" (did you mean {' or '.join(map(repr, close))}?)"


def _prefixed(source: str, message: str) -> str:
    return f"{source}: {message}" if source else message


def unknown_name_error(kind: str, name: str, known: Iterable[str], source: str = "", hint: str = "",
                       plural: str | None = None) -> InputError:
    """The error for a name that is not one of ``known``, with the closest known names.

    ``kind`` says what the name is (``"method"``, ``"system"``, ``"output"``...), ``source``
    the file it comes from (put in front), ``hint`` a last sentence; the known names are
    listed sorted, e.g. ``unknown method 'rattle2' (did you mean 'rattle'?); known methods:
    ...``. The caller raises it.
    """
    names = sorted(set(map(str, known)))
    listed = ", ".join(names) or "(none)"
    message = f"unknown {kind} {name!r}{did_you_mean(name, names)}; known {plural or kind + 's'}: {listed}"
    return InputError(_prefixed(source, f"{message}; {hint}" if hint else message))


def check_known_keys(table: dict, known: Iterable[str], where: str, source: str = "", kind: str = "key") -> None:
    """Raise :class:`InputError` when ``table`` has keys outside ``known``.

    The message names the file (``source``), the table (``where``, e.g. ``"[run]"``), each
    unknown key with the closest known ones, and the known keys sorted, e.g.
    ``scene.toml: [run] has an unknown key 'sample' (did you mean 'samples'?); known keys:
    dt, method, ...``. ``kind`` is ``"key"`` or, for the tables of a file, ``"section"``.
    """
    names = sorted(set(map(str, known)))
    unknown = sorted(str(key) for key in table if str(key) not in names)
    if not unknown:
        return
    each = ", ".join(f"{key!r}{did_you_mean(key, names)}" for key in unknown)
    what = f"an unknown {kind}" if len(unknown) == 1 else f"unknown {kind}s"
    listed = ", ".join(names) or "(none)"
    raise InputError(_prefixed(source, f"{where} has {what} {each}; known {kind}s: {listed}"))
