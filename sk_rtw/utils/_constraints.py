"""The values a declared parameter accepts: constraints with their checks and descriptions.

A :class:`Constraint` says whether a value is accepted, gives its canonical form (string
options lower-cased, integers as ``int``) and describes itself twice: as a numpydoc type
(``int >= 1``) and in an error message (``an integer >= 1``). :func:`check_value` runs a
parameter's constraints in order, in the shape of scikit-learn's private
``_parameter_constraints``; :class:`~sk_rtw.utils._params.Parameter` holds them.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from numbers import Integral, Real
from typing import Any

import numpy as np

#: The sentinel of every knob whose value a preset gives.
AUTO = "auto"


class InvalidParameterError(ValueError, TypeError):
    """A parameter value outside what the parameter accepts.

    Both a ``ValueError`` and a ``TypeError``, as scikit-learn's: callers catching either
    keep working.
    """


class Constraint:
    """Values a parameter accepts: :meth:`accepts`, a canonical form, two descriptions."""

    #: Numpydoc type, e.g. ``int >= 1``.
    short: str = "object"
    #: The same in an error message, e.g. ``an integer >= 1``.
    description: str = "an object"

    def accepts(self, value: Any) -> bool:
        raise NotImplementedError

    def normalise(self, name: str, value: Any) -> Any:
        """The canonical form of an accepted value (may raise a more specific error)."""
        return value


@dataclass(frozen=True)
class Interval(Constraint):
    """Integers or finite reals between bounds; ``closed`` says which bounds belong."""

    kind: type  # int or float
    low: float | None = None
    high: float | None = None
    closed: str = "both"  # "both", "left", "right", "neither"

    def accepts(self, value: Any) -> bool:
        if isinstance(value, (bool, np.bool_)):
            return False
        if self.kind is int:
            if not isinstance(value, Integral):
                return False
        elif not isinstance(value, Real) or not math.isfinite(value):
            return False
        left = self.closed in ("both", "left")
        right = self.closed in ("both", "right")
        if self.low is not None and (value < self.low or (value == self.low and not left)):
            return False
        return self.high is None or not (value > self.high or (value == self.high and not right))

    def normalise(self, name: str, value: Any) -> Any:
        return int(value) if self.kind is int else float(value)

    def _bounds(self) -> str:
        left = ">=" if self.closed in ("both", "left") else ">"
        right = "<=" if self.closed in ("both", "right") else "<"
        if self.low is not None and self.high is not None:
            lo = "[" if left == ">=" else "("
            hi = "]" if right == "<=" else ")"
            return f"in {lo}{_number(self.low)}, {_number(self.high)}{hi}"
        if self.low is not None:
            return f"{left} {_number(self.low)}"
        if self.high is not None:
            return f"{right} {_number(self.high)}"
        return ""

    @property
    def short(self) -> str:  # type: ignore[override]
        return f"{'int' if self.kind is int else 'float'} {self._bounds()}".strip()

    @property
    def description(self) -> str:  # type: ignore[override]
        noun = "an integer" if self.kind is int else "a finite number"
        return f"{noun} {self._bounds()}".strip()


def _number(value: float) -> str:
    return str(int(value)) if float(value).is_integer() else f"{value:g}"


@dataclass(frozen=True)
class Options(Constraint):
    """One of a few strings, in any case; normalised to lower case."""

    values: tuple[str, ...]

    def accepts(self, value: Any) -> bool:
        return isinstance(value, str) and value.lower() in self.values

    def normalise(self, name: str, value: Any) -> Any:
        return value.lower()

    @property
    def short(self) -> str:  # type: ignore[override]
        if len(self.values) == 1:
            return f'"{self.values[0]}"'
        return "{" + ", ".join(f'"{v}"' for v in self.values) + "}"

    @property
    def description(self) -> str:  # type: ignore[override]
        if len(self.values) == 1:
            return f'"{self.values[0]}"'
        return "one of " + ", ".join(f'"{v}"' for v in self.values)


@dataclass(frozen=True)
class Constant(Constraint):
    """Exactly this value (``None``: "off"); ``meaning`` says what it does."""

    value: Any
    meaning: str = ""

    def accepts(self, value: Any) -> bool:
        return value is self.value

    @property
    def short(self) -> str:  # type: ignore[override]
        return repr(self.value)

    @property
    def description(self) -> str:  # type: ignore[override]
        return repr(self.value) + (f" ({self.meaning})" if self.meaning else "")


@dataclass(frozen=True)
class Boolean(Constraint):
    short = "bool"
    description = "True or False"

    def accepts(self, value: Any) -> bool:
        return isinstance(value, (bool, np.bool_))

    def normalise(self, name: str, value: Any) -> Any:
        return bool(value)


@dataclass(frozen=True)
class _Described(Constraint):
    """A constraint whose two descriptions are given as text."""

    short_text: str
    description_text: str

    @property
    def short(self) -> str:  # type: ignore[override]
        return self.short_text

    @property
    def description(self) -> str:  # type: ignore[override]
        return self.description_text


@dataclass(frozen=True)
class InstanceOf(_Described):
    """An instance of one of ``types``; ``normaliser(name, value)`` may refine it."""

    types: tuple[type, ...] = ()
    normaliser: Callable[[str, Any], Any] | None = None

    def accepts(self, value: Any) -> bool:
        return isinstance(value, self.types)

    def normalise(self, name: str, value: Any) -> Any:
        return value if self.normaliser is None else self.normaliser(name, value)


@dataclass(frozen=True)
class Satisfies(_Described):
    """Any value for which ``predicate`` holds (for rules no interval states); strings
    come back lower-cased, as :class:`Options`'."""

    predicate: Callable[[Any], bool] = bool

    def accepts(self, value: Any) -> bool:
        return bool(self.predicate(value))

    def normalise(self, name: str, value: Any) -> Any:
        return value.lower() if isinstance(value, str) else value


def check_value(name: str, value: Any, constraints: Sequence[Constraint]) -> Any:
    """The canonical form of ``value`` under the first constraint that accepts it.

    Raises
    ------
    InvalidParameterError
        ``"<name> must be <a> or <b>, got <value>"``.
    """
    for constraint in constraints:
        if constraint.accepts(value):
            return constraint.normalise(name, value)
    allowed = " or ".join(c.description for c in constraints)
    raise InvalidParameterError(f"{name} must be {allowed}, got {value!r}")
