"""Settings declared once: a :class:`Param` in a field's annotation is the setting's type, unit,
bounds, help and display, and pydantic checks it on construction and on every
``dataclasses.replace`` (docs/design.md, "Adding a setting").

:func:`settings` turns a class of such fields into a frozen pydantic dataclass whose refusals
are one :class:`SettingError` line naming the setting, the value and the allowed range. The
preset reader, the simulations' setters, the preset writer, the panel and the command line all
read the same declarations (:func:`params_of`), so no range is written twice.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import operator
import types
import typing
from dataclasses import dataclass

import pydantic
from pydantic import ConfigDict, ValidationError
from pydantic_core import core_schema

__all__ = ["Param", "SettingError", "settings", "params_of", "describe"]


@dataclass(frozen=True)
class Param:
    """The declaration of one number: its bounds, unit, help and how the panel shows it.

    ``Annotated[float, Param(0, 1e12, lo_open=True, unit="N·m²", help=...)] = 2.5e4`` declares
    a float in (0, 1e12] with default 2.5e4; ``tuple[X, X]`` of such an annotation, a pair;
    ``X | None`` (default None), a number or None (the owner's "automatic");
    ``Annotated[int, Param(4, 256, integer=True)]``, an integer.

    Attributes
    ----------
    lo, hi : float
        The allowed range, [lo, hi] (or (lo, hi] where ``lo_open``): what keeps every state of
        the simulation finite, not what is plausible.
    lo_open : bool
        Whether ``lo`` itself is refused.
    unit : str
        SI unit ('' for a ratio or a count).
    help : str
        One sentence or a few: what it is and what it does.
    label : str
        Short name for a widget ('' : the setting's name).
    fmt : str
        printf format of a widget showing it (the unit is appended).
    log : bool
        A slider over it is logarithmic.
    integer : bool
        An integer (any int or numpy integer; bools and floats refused), not a float.
    """

    lo: float
    hi: float
    lo_open: bool = False
    unit: str = ""
    help: str = ""
    label: str = ""
    fmt: str = "%.3g"
    log: bool = False
    integer: bool = False

    @property
    def interval(self) -> str:
        """The range as text: ``(0, 1e+12]``, ``[0, 100]`` or ``[0, inf)``."""
        return f"{'(' if self.lo_open else '['}{self.lo:g}, {self.hi:g}{')' if self.hi == math.inf else ']'}"

    @property
    def expected(self) -> str:
        """What a value must be, for messages: ``a number in (0, 1e+12]``, ``an integer in [4,
        256]``, ``a finite number`` (no bounds)."""
        what = "an integer" if self.integer else "a number"
        if self.lo == -math.inf and self.hi == math.inf:
            return f"a finite {what.split()[-1]}"
        return f"{what} in {self.interval}"

    @property
    def widget_format(self) -> str:
        """:attr:`fmt` with the unit."""
        return f"{self.fmt} {self.unit}" if self.unit else self.fmt

    def __get_pydantic_core_schema__(self, source, handler):
        # A strict float (bools and strings refused, any int or numpy number taken), finite, in
        # range; -0.0 stored as 0.0. An integer: any int or numpy integer (operator.index),
        # in range; bools, floats and strings refused.
        bound = {"gt" if self.lo_open else "ge": self.lo, "le": self.hi}
        bound = {k: v for k, v in bound.items() if math.isfinite(v)}
        if self.integer:
            return core_schema.no_info_before_validator_function(_index, core_schema.int_schema(strict=True, **bound))
        number = core_schema.float_schema(strict=True, allow_inf_nan=False, **bound)
        return core_schema.no_info_after_validator_function(lambda x: x + 0.0, number)


def _index(x):
    """``x`` as an int where it is an integer of any kind but a bool; else ``x`` unchanged (for
    the strict integer check to refuse)."""
    if isinstance(x, bool):
        return x
    try:
        return operator.index(x)
    except TypeError:
        return x


class SettingError(ValueError):
    """A value refused by its declaration: one line, ``KEY: PROBLEM``.

    Attributes
    ----------
    key : str
        The setting's dotted name, e.g. ``physics.summer.branch.f``.
    problem : str
        What was wrong, e.g. ``expected a number in (0, 1e+12], got -3.0``.
    """

    def __init__(self, key: str, problem: str):
        super().__init__(f"{key}: {problem}")
        self.key, self.problem = key, problem


#: Each class :func:`settings` made: the prefix of its keys in messages.
_PREFIX: dict[type, str] = {}


def settings(prefix: str):
    """Class decorator: a frozen pydantic dataclass of declared fields, whose construction (and so
    ``dataclasses.replace``) raises :class:`SettingError` on the first refused value.

    Nested tables may be given as dicts and pairs as lists (as TOML has them); numbers are never
    converted from strings or bools. Unknown keywords are refused. An empty ``prefix`` names
    the settings by their keys alone (``turbulence: expected ...``).
    """

    def wrap(cls):
        cls = pydantic.dataclasses.dataclass(frozen=True, config=ConfigDict(extra="forbid"))(cls)
        init = cls.__init__

        @functools.wraps(init)
        def __init__(self, *args, **kwargs):
            try:
                init(self, *args, **kwargs)
            except ValidationError as e:
                raise _error(cls, e) from None

        cls.__init__ = __init__
        _PREFIX[cls] = prefix
        return cls

    return wrap


def _hints(cls) -> dict:
    return typing.get_type_hints(cls, include_extras=True)


def _param(hint) -> Param | None:
    """The Param of ``Annotated[float, Param]``, ``tuple[that, that]`` or ``that | None``."""
    if typing.get_origin(hint) is typing.Annotated:
        return next((m for m in hint.__metadata__ if isinstance(m, Param)), None)
    if typing.get_origin(hint) is tuple:
        return _param(typing.get_args(hint)[0])
    if typing.get_origin(hint) in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(hint) if a is not type(None)]
        return _param(args[0]) if len(args) == 1 else None
    return None


def _table(hint):
    """The settings class of ``hint`` (or of ``hint | None``), else None."""
    if typing.get_origin(hint) in (typing.Union, types.UnionType):
        return next((t for t in typing.get_args(hint) if t in _PREFIX), None)
    return hint if hint in _PREFIX else None


def _is_pair(hint) -> bool:
    return typing.get_origin(hint) is tuple


def _is_optional(hint) -> bool:
    return typing.get_origin(hint) in (typing.Union, types.UnionType) and type(None) in typing.get_args(hint)


def params_of(cls) -> dict[str, Param]:
    """The declared numbers of settings class ``cls`` (its own, not its nested tables'), by
    field name, in declaration order."""
    hints = _hints(cls)
    return {f.name: p for f in dataclasses.fields(cls) if (p := _param(hints[f.name])) is not None}


def default_of(cls, name: str):
    """The default of field ``name`` of ``cls``."""
    f = cls.__dataclass_fields__[name]
    return f.default_factory() if f.default is dataclasses.MISSING else f.default


def describe(value) -> str:
    """A value for a message, cut to 40 characters."""
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _error(cls, e: ValidationError) -> SettingError:
    """The first of ``e``'s errors as one line naming the key, the value and what was expected."""
    err = e.errors(include_url=False)[0]
    raw = list(err["loc"])
    if raw and isinstance(raw[0], int):  # a positional argument: its field
        raw[0] = dataclasses.fields(cls)[raw[0]].name
    loc = [x for x in raw if isinstance(x, str)]
    element = bool(raw) and isinstance(raw[-1], int)  # one number of a pair
    kind, value = err["type"], err.get("input")
    # walk the key down the nested tables to the class and the field it names
    owner, hint = cls, None
    for i, name in enumerate(loc):
        hints = _hints(owner)
        if name not in hints:
            break
        hint = hints[name]
        nested = _table(hint)
        if nested is None or i == len(loc) - 1:
            break
        owner = nested
    key = ".".join([x for x in (_PREFIX[cls], *loc) if x]) or cls.__name__
    param = _param(hint) if hint is not None else None
    if kind in ("unexpected_keyword_argument", "extra_forbidden"):
        names = ", ".join(f.name for f in dataclasses.fields(owner))
        return SettingError(key, f"unknown key; expected one of {names}")
    pair = param is not None and _is_pair(hint)
    if kind in ("missing_argument", "missing") and not (pair and element):
        return SettingError(key, "missing; expected [min, max]" if pair else "missing")
    if kind == "value_error":
        return SettingError(key, str(err["ctx"]["error"]))
    if pair and (not element or kind == "missing"):
        return SettingError(key, f"expected a pair [min, max] of numbers in {param.interval}, got {describe(value)}")
    if param is not None:
        optional = value is not None and _is_optional(hint)
        return SettingError(key, f"expected {param.expected}{' or None' if optional else ''}, got {describe(value)}")
    if kind.startswith(("dataclass", "model")) or _table(hint) is not None:
        return SettingError(key, f"expected a table, got {describe(value)}")
    return SettingError(key, f"{err['msg']}, got {describe(value)}")
