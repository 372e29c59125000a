"""Declared parameters: each one written once, and checked, signed and documented from that.

A :class:`Parameter` is a name, the values it accepts (a tuple of
:class:`~sk_rtw.utils._constraints.Constraint`)
and a one-line description with its unit. A class writes its ``__init__`` by hand
(parameters stored unchanged, scikit-learn's rule: static tools and IDEs see the real
signature) and lists the parameters it takes with its defaults
(:func:`declare_parameters`); from that list come

* the check that the written signature is the declared one (names, order, defaults,
  which are keyword-only), made when the class is defined,
* the check run once at the start of ``fit`` (:func:`validate_parameters`), in the shape
  of scikit-learn's ``_parameter_constraints`` (written here: that module is private),
* the "Parameters" section of its docstring,
* for an unknown keyword, a ``TypeError`` that says where the setting belongs.

String options are case-insensitive and come back lower-cased. ``"auto"`` is the one
sentinel for "the preset's value" and ``None`` for "off" (no band, no early stop, ...).
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, TypeVar

from ._constraints import AUTO, Constraint, Options, check_value


@dataclass(frozen=True)
class Parameter:
    """One declared parameter.

    Attributes
    ----------
    name : str
    constraints : tuple of Constraint
        The value must satisfy one of them.
    doc : str
        What it sets, with its unit (the first line is the summary; more lines may follow).
    """

    name: str
    constraints: tuple[Constraint, ...]
    doc: str

    def check(self, value: Any, name: str | None = None) -> Any:
        """``value`` in canonical form, or
        :class:`~sk_rtw.utils._constraints.InvalidParameterError` naming the rule."""
        return check_value(name or self.name, value, self.constraints)

    def type_doc(self) -> str:
        return " or ".join(c.short for c in self.constraints)

    def with_auto(self) -> Parameter:
        """The same parameter accepting ``"auto"`` (the preset's value) as well."""
        if any(isinstance(c, Options) and c.values == (AUTO,) for c in self.constraints):
            return self
        return Parameter(self.name, (*self.constraints, Options((AUTO,))), self.doc)


@dataclass(frozen=True)
class Declaration:
    """The parameters of one class, in signature order, with that class's defaults."""

    parameters: tuple[Parameter, ...]
    defaults: Mapping[str, Any]
    positional: int = 1
    hint: Callable[[str], str] | None = field(default=None, compare=False)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.parameters)

    def __getitem__(self, name: str) -> Parameter:
        for parameter in self.parameters:
            if parameter.name == name:
                return parameter
        raise KeyError(name)

    def signature(self) -> inspect.Signature:
        kinds = [
            inspect.Parameter.POSITIONAL_OR_KEYWORD if i < self.positional
            else inspect.Parameter.KEYWORD_ONLY
            for i in range(len(self.parameters))
        ]  # fmt: skip
        return inspect.Signature(
            [inspect.Parameter("self", inspect.Parameter.POSITIONAL_OR_KEYWORD)]
            + [
                inspect.Parameter(p.name, kind, default=self.defaults[p.name])
                for p, kind in zip(self.parameters, kinds, strict=True)
            ]
        )

    def docs(self, notes: Mapping[str, str] | None = None) -> str:
        """The numpydoc "Parameters" entries, one per parameter, with optional notes."""
        notes = notes or {}
        lines = []
        for p in self.parameters:
            default = self.defaults[p.name]
            text = f'"{default}"' if isinstance(default, str) else repr(default)
            lines.append(f"{p.name} : {p.type_doc()}, default={text}")
            body = p.doc + (f" {notes[p.name]}" if p.name in notes else "")
            lines.extend("    " + line for line in wrap(body))
        return "\n".join(lines)


def wrap(text: str, width: int = 84) -> list[str]:
    """``text`` in lines of at most ``width`` characters, paragraph by paragraph."""
    import textwrap

    out: list[str] = []
    for paragraph in text.split("\n"):
        out.extend(textwrap.wrap(paragraph, width) or [""])
    return out


PARAMETERS_MARKER = "%(parameters)s"


_Class = TypeVar("_Class", bound=type)


def declare_parameters(
    parameters: Sequence[Parameter] | None = None,
    defaults: Mapping[str, Any] | None = None,
    *,
    positional: int = 1,
    hint: Callable[[str], str] | None = None,
    notes: Mapping[str, str] | None = None,
) -> Callable[[_Class], _Class]:
    """Class decorator: the check table and the docs from ``parameters``, checked against
    the class's written ``__init__``.

    Parameters
    ----------
    parameters : sequence of Parameter, optional
        In signature order; default: the parent class's declaration (a subclass that only
        changes ``defaults``).
    defaults : mapping, optional
        Default of every parameter (merged over the parent's when ``parameters`` is
        omitted).
    positional : int, default=1
        How many leading parameters may be passed by position.
    hint : callable, optional
        ``hint(name)`` is appended to the ``TypeError`` for an unknown keyword.
    notes : mapping, optional
        Class-specific text appended to a parameter's documentation.

    Raises
    ------
    TypeError
        When the class's own ``__init__`` is not the declared signature.

    The class docstring's ``%(parameters)s`` marker is replaced by the numpydoc entries.
    """

    def decorate(cls: _Class) -> _Class:
        parent = getattr(cls, "_declaration", None)
        if parameters is None:
            if parent is None:
                raise TypeError(f"{cls.__name__} declares no parameters and inherits none")
            declaration = Declaration(
                parent.parameters, {**parent.defaults, **(defaults or {})},
                parent.positional, hint or parent.hint,
            )  # fmt: skip
        else:
            missing = [p.name for p in parameters if p.name not in (defaults or {})]
            if missing:
                raise TypeError(f"{cls.__name__}: no default for {missing}")
            declaration = Declaration(tuple(parameters), dict(defaults or {}), positional, hint)
        check_signature(cls, declaration)
        cls._declaration = declaration  # type: ignore[attr-defined]
        cls.__init__ = _with_hint(cls.__dict__["__init__"], declaration)  # type: ignore[misc]
        if cls.__doc__ and PARAMETERS_MARKER in cls.__doc__:
            block = indent(declaration.docs(notes), doc_indent(cls.__doc__))
            cls.__doc__ = cls.__doc__.replace(PARAMETERS_MARKER, block.lstrip())
        return cls

    return decorate


def check_signature(cls: type, declaration: Declaration) -> None:
    """``TypeError`` unless ``cls`` writes its own ``__init__`` with exactly the declared
    parameters: names, order, defaults and which may be passed by position."""
    init = cls.__dict__.get("__init__")
    if init is None:
        raise TypeError(
            f"{cls.__name__} must write its own __init__ (scikit-learn's rule: every "
            "parameter a keyword of the class's signature)"
        )

    def shape(signature: inspect.Signature) -> list[tuple[str, Any, Any]]:
        return [(p.name, p.kind, p.default) for p in signature.parameters.values()]

    written, declared = shape(inspect.signature(init)), shape(declaration.signature())
    if written != declared:
        raise TypeError(
            f"{cls.__name__}.__init__ differs from its declared parameters: written "
            f"{inspect.signature(init)}, declared {declaration.signature()}"
        )


def check_signature_defaults(function: Callable[..., Any], declaration: Declaration) -> None:
    """``TypeError`` unless every declared parameter is a keyword of ``function`` with the
    declared default (a function's written signature against its declaration)."""
    written = inspect.signature(function).parameters
    for name, default in declaration.defaults.items():
        if name not in written or written[name].default != default:
            raise TypeError(
                f"{function.__name__}'s signature differs from its declaration at {name!r}"
            )


def _with_hint(init: Callable[..., None], declaration: Declaration) -> Callable[..., None]:
    """``init`` itself, except that an unknown keyword's ``TypeError`` says where the
    setting belongs (the declaration's ``hint``)."""
    if declaration.hint is None:
        return init
    names = set(declaration.names)

    @functools.wraps(init)
    def __init__(self: Any, *args: Any, **kwargs: Any) -> None:
        unknown = [k for k in kwargs if k not in names]
        if unknown:
            text = f"{type(self).__name__}() got an unexpected keyword argument {unknown[0]!r}"
            raise TypeError(f"{text}; {declaration.hint(unknown[0])}")  # type: ignore[misc]
        init(self, *args, **kwargs)

    return __init__


def doc_indent(doc: str, marker: str = PARAMETERS_MARKER) -> str:
    """The indentation of the docstring line holding ``marker``."""
    for line in doc.splitlines():
        if marker in line:
            return line[: len(line) - len(line.lstrip())]
    return ""


def indent(text: str, prefix: str) -> str:
    """Every non-empty line of ``text`` prefixed."""
    return "\n".join(prefix + line if line else line for line in text.splitlines())


def drop_auto(values: Mapping[str, Any]) -> dict[str, Any]:
    """``values`` without the entries left ``"auto"`` (the preset's value)."""
    return {k: v for k, v in values.items() if not (isinstance(v, str) and v == AUTO)}


def validate_parameters(obj: Any, names: Sequence[str] | None = None) -> dict[str, Any]:
    """Check ``obj``'s declared parameters; their canonical values, by name.

    Parameters
    ----------
    obj : object
        An instance of a class decorated with :func:`declare_parameters`.
    names : sequence of str, optional
        Only these parameters (default: all).

    Returns
    -------
    dict
        Parameter name to canonical value (lower-cased options, ints, floats).
    """
    declaration: Declaration = type(obj)._declaration
    wanted = declaration.names if names is None else tuple(names)
    return {name: declaration[name].check(getattr(obj, name)) for name in wanted}
