"""Errors about the arguments of :func:`dirac.ensemble.engine.run_ensemble`, spelled for the caller.

A Python caller passes keyword arguments (``out=``, ``chunk_size=``); a command-line user
passes flags (``--out``, ``--chunk-size``). An :class:`ArgumentError` keeps the names and
values of the arguments it is about apart from its text, so that its message names them
as keyword arguments (``str(error)``) and the command line can spell them as its flags
(:meth:`ArgumentError.spelled`).
"""

from __future__ import annotations

from collections.abc import Callable

from dirac.errors import InputError

__all__ = ["ArgumentError", "keyword_spelling"]


def keyword_spelling(name: str, value: object) -> str:
    """``("chunk_size", 10)`` -> ``"chunk_size=10"``; ``("out", "runs/a")`` -> ``"out='runs/a'"``."""
    return f"{name}={value!r}"


class ArgumentError(InputError):
    """An input error about named arguments of :func:`~dirac.ensemble.engine.run_ensemble`.

    Parameters
    ----------
    template : str
        The message, with one ``{name}`` field per argument it names and per detail.
    arguments : dict
        Argument name -> the value to show (``out`` as a string, ``chunk_size`` as an int).
    **details
        Other fields of ``template``, shown as they are (``str.format``).
    """

    def __init__(self, template: str, arguments: dict[str, object], **details: object) -> None:
        self.template = template
        self.arguments = dict(arguments)
        self.details = details
        super().__init__(self.spelled(keyword_spelling))

    def spelled(self, spell: Callable[[str, object], str]) -> str:
        """The message with every argument written by ``spell(name, value)``."""
        spelled = {name: spell(name, value) for name, value in self.arguments.items()}
        return self.template.format(**self.details, **spelled)
