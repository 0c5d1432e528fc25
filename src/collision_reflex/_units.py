"""The package's one pint unit registry, and the one reader of quantity strings (``"60 mm"``, ``"1.3 N*m"``).

Building a registry takes a while, and quantities from two registries cannot be combined.

Quantity strings come from files a user may not have written (study files, catalogues), so they are read with
a bounded grammar: a number, then a unit expression of unit names joined by ``*``, ``/``, ``·`` or spaces, each
name with an optional small integer power (``^2``, ``**-1``). pint only sees text of that form. Its own parser
evaluates arbitrary expressions: ``10**10**10`` would be a big-integer computation that never ends, and its
time grows with the square of the text's length.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import math
import os
import re
import sys
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import pint

MAX_QUANTITY_LENGTH = 100
"""Longest quantity string read [characters]; ``"2.21e-5 kg*m^2"`` is 14."""

_NUMBER = r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d{1,4})?"
_NAME = r"(?:[^\W\d_]\w*|°)"
_POWER = r"(?:\^|\*\*)\s*(?:[+-]?\d{1,2}|\(\s*[+-]?\d{1,2}\s*\))"
_FACTOR = rf"{_NAME}(?:\s*{_POWER})?"
_UNIT = rf"{_FACTOR}(?:\s*[*/·]\s*{_FACTOR}|\s+{_FACTOR})*"
_QUANTITY = re.compile(rf"\s*(?P<number>{_NUMBER})\s*(?P<unit>{_UNIT})?\s*")
_UNIT_TEXT = re.compile(rf"\s*{_UNIT}\s*")
_GRAMMAR = "a number and a unit, e.g. '60 mm', '1.3 N*m' or '2.21e-5 kg*m^2'"


class QuantityError(ValueError):
    """A quantity string that cannot be used; ``reason`` says why in a short phrase.

    Attributes
    ----------
    kind: ``"syntax"`` (not a number and a unit), ``"unit"`` (an unknown unit name), ``"dimension"`` (a unit of
        another kind than the one asked for), ``"angle"`` (an angular speed without an angle unit) or
        ``"value"`` (not finite once converted).
    reason: what is wrong, without quoting the text.
    found_dimension, dimension: the text's dimension and the one asked for (``kind == "dimension"``).
    """

    def __init__(self, kind: str, reason: str, found_dimension: str = "", dimension: str = "") -> None:
        super().__init__(reason)
        self.kind = kind
        self.reason = reason
        self.found_dimension = found_dimension
        self.dimension = dimension


# The registry holds the part of pint's own definitions file (``default_en.txt``) that datasheets and studies
# use: pint's whole registry is much slower to build, and ``crx`` builds one at every start. The definitions
# are pint's lines, picked by name here (two groups and the mks system whole), never copied. Kept: SI base and
# derived units with every prefix, angles (deg, turn, arcmin), rpm and rps, time, temperature, the
# international inch/foot/yard/mile, the avoirdupois pound and ounce with their forces (lbf, ozf), kgf and gf,
# and the power, pressure and electrical units of motor datasheets. Also kept: every unit whose name the
# smaller registry would otherwise read as a prefix and another unit ("kt" would be kilo-tonne without the
# knot, "pt" pico-tonne without the pint, "pc" pico-c without the parsec): a unit pint's default registry
# knows is read identically here or refused, never read as another (tests/test_study_units.py checks every
# name, plural and prefix of pint's default registry).
_KEPT_BLOCKS = frozenset(
    {
        "@defaults",
        "@group USCSLengthInternational",
        "@group Avoirdupois",
        "@system mks using international",
    }
)
_DATASHEET_UNITS = """
    meter second ampere candela gram mole kelvin radian bit count pi standard_gravity standard_atmosphere
    turn degree arcminute arcsecond steradian percent permille ppm micron metric_ton grain carat
    minute hour day degree_Celsius degree_Fahrenheit degree_Rankine liter cubic_centimeter
    hertz revolutions_per_minute revolutions_per_second counts_per_second
    mile_per_hour kilometer_per_hour meter_per_second foot_per_second meter_per_second_squared
    newton dyne force_kilogram force_gram force_metric_ton joule erg watt_hour
    watt volt_ampere horsepower metric_horsepower electrical_horsepower
    pascal bar torr pound_force_per_square_inch kip_per_square_inch foot_pound
    coulomb ampere_hour volt ohm siemens farad weber henry tesla
"""
# Kept only for their names (and what they are defined with): Eh, Rd, Td, at, hbar, kt, nmi, rads, bps, kat,
# pc, fm, mil, pt, qt, dpi, dqt, dgal, rd, ppi, Tt.
_UNITS_FOR_THEIR_NAMES = """
    hartree rydberg planck_constant speed_of_light rydberg_constant dirac_constant rutherford becquerel
    townsend technical_atmosphere knot nautical_mile rads gray baud katal parsec tansec astronomical_unit
    fermi mil pint quart gallon dry_pint dry_quart dry_gallon bushel rod survey_foot pixels_per_inch pixel
    tex
"""
_KEPT_UNITS = frozenset(_DATASHEET_UNITS.split() + _UNITS_FOR_THEIR_NAMES.split())

# pint.compat imports Dask, SciPy and Babel when they are installed, for integrations the package never uses
# (Quantity-wrapped Dask arrays, `to_preferred`, locale formatting), slowing every start of `crx`. The `crx`
# command's own process imports pint without them (:func:`hide_pint_extras`); library users keep all of pint.
_PINT_EXTRAS = ("dask", "scipy", "babel")
_hide_extras = False
# Parsing the definitions and working out every unit's base units would be redone at each start of `crx`. The
# `crx` command keeps pint's parse of them in the user's cache folder (:func:`cache_registry`); a library user's
# registry writes nothing.
_use_cache = False


def hide_pint_extras() -> None:
    """Import pint, when it is first needed, without its optional integrations (for the ``crx`` command)."""
    global _hide_extras
    _hide_extras = True


def cache_registry() -> None:
    """Build the registry, when it is first needed, through pint's on-disk cache (for the ``crx`` command)."""
    global _use_cache
    _use_cache = True


def import_pint() -> Any:
    """pint, imported (without the extras after :func:`hide_pint_extras`, if pint is not imported yet)."""
    if not _hide_extras or "pint" in sys.modules:
        import pint

        return pint
    hidden = [name for name in _PINT_EXTRAS if name not in sys.modules]
    for name in hidden:
        sys.modules[name] = None  # type: ignore[assignment]  # `import dask` fails, find_spec gives None
    try:
        import pint
    finally:
        for name in hidden:  # importable again for the code that uses them
            if name in sys.modules and sys.modules[name] is None:
                del sys.modules[name]
    return pint


def registry_definitions() -> list[str] | None:
    """The lines of pint's definitions file the registry is built from.

    None if one of the kept names is missing from the installed pint's file: the registry is then pint's
    whole default one.
    """
    folder = resources.files("pint")

    def lines(name: str) -> Any:
        for line in folder.joinpath(name).read_text(encoding="utf-8").splitlines():
            text = line.split("#", 1)[0].rstrip()
            if text.strip().startswith("@import"):
                yield from lines(text.split()[1])
            elif text.strip():
                yield text

    kept: list[str] = []
    found: set[str] = set()
    block = ""  # the block a line is in: "" outside any, else its first line ("@group Avoirdupois")
    for line in lines("default_en.txt"):
        text = line.strip()
        if text.startswith("@"):
            block = block if text == "@end" else " ".join(text.split())
            if block in _KEPT_BLOCKS:  # its first and last lines
                kept.append(line)
                found.add(block)
            block = "" if text == "@end" else block
            continue
        name = text.split("=", 1)[0].strip()
        if block in _KEPT_BLOCKS:  # @defaults, a @group or a @system kept whole
            kept.append(line)
        elif name.endswith("-") and not block:
            kept.append(line)  # every prefix
        elif name in _KEPT_UNITS and (not block or block.startswith("@group")):
            kept.append(text)  # a unit of a group not kept whole goes to the default group
            found.add(name)
        # Left out: the named dimensions ("[force] = ..."), which no quantity of the bounded grammar names,
        # and the conversions of every @context.
    return kept if found == _KEPT_UNITS | _KEPT_BLOCKS else None


@functools.cache
def unit_registry() -> pint.UnitRegistry:
    """The registry every unit string of the package is read with: study files, catalogues, traces."""
    pint = import_pint()
    definitions = registry_definitions()
    if definitions is None:
        registry = pint.UnitRegistry()
    else:
        cached = cached_registry(definitions, registry_cache_folder()) if _use_cache else None
        registry = pint.UnitRegistry(definitions) if cached is None else cached
    registry.define("@alias turn = rev")  # datasheets' "counts/rev", "mm/rev"; not a name of pint's own
    return registry


def registry_cache_folder() -> Path | None:
    """The folder of the registry's cache: ``units`` in the user's cache folder (None if there is none)."""
    import platformdirs  # a dependency of pint

    try:
        return platformdirs.user_cache_path("collision-reflex", appauthor=False) / "units"
    except (OSError, RuntimeError, KeyError):  # no home folder
        return None


def cached_registry(definitions: list[str], folder: Path | None) -> pint.UnitRegistry | None:
    """A registry of ``definitions`` built through pint's cache in ``folder``, or None if it cannot be used.

    The definitions are written to a file named by their hash, which pint reads with ``cache_folder``: pint
    keeps its parse of the file, keyed by the file's content, its own version and the number type, and skips
    listing every unit's base units (it works them out when a unit is first used, as it does for a unit
    defined later). A folder per pint and flexparser (its parser) version, so that no parse is read back into
    another version's classes. A read-only or missing folder, or one that cannot be created, is not used; an
    unreadable cache file is deleted and the cache built again.

    Parameters
    ----------
    definitions : list of str
        The lines of the registry (:func:`registry_definitions`).
    folder : Path or None
        Where the caches of every version go (:func:`registry_cache_folder`).
    """
    pint = import_pint()
    import flexparser  # a dependency of pint

    if folder is None:
        return None
    text = "\n".join(definitions) + "\n"
    folder = folder / f"pint-{pint.__version__}-flexparser-{flexparser.__version__}"
    path = folder / f"definitions-{hashlib.sha256(text.encode()).hexdigest()[:16]}.txt"
    try:
        folder.mkdir(parents=True, exist_ok=True)
        if not os.access(folder, os.W_OK):
            return None
        if not path.is_file() or path.read_text(encoding="utf-8") != text:
            partial = path.with_name(f"{path.name}.{os.getpid()}.tmp")
            partial.write_text(text, encoding="utf-8")
            os.replace(partial, path)  # whole or absent for a process reading it at the same time
    except (OSError, UnicodeDecodeError):
        return None
    for _ in range(2):
        try:
            return pint.UnitRegistry(path, cache_folder=folder)
        except Exception:  # a cache file cut short or unreadable: delete pint's files, build them again once
            with contextlib.suppress(OSError):
                for stale in (*folder.glob("*.pickle"), *folder.glob("*.json")):
                    stale.unlink(missing_ok=True)
    return None


@functools.lru_cache(maxsize=4096)  # files repeat their units, and a pint conversion is slow beside a look-up
def parse_quantity(text: str, unit: str, *, angle_explicit: bool = False) -> float:
    """The quantity ``text`` (e.g. ``"60 mm"``, or a bare number taken in ``unit``) as a float in ``unit``.

    Parameters
    ----------
    text : str
        A number with an optional unit expression, at most :data:`MAX_QUANTITY_LENGTH` characters.
    unit : str
        The unit of the result (pint syntax, e.g. ``"N*m/rad"``); it also fixes the dimension asked for.
    angle_explicit : bool
        Refuse a text whose power of the angle differs from ``unit``'s: pint takes angles as dimensionless,
        so ``"50 Hz"`` would pass as 50 rad/s, though a datasheet may mean 50 rev/s.

    Raises
    ------
    QuantityError
        Saying why the text is not a quantity of ``unit``'s dimension.
    """
    if len(text) > MAX_QUANTITY_LENGTH:
        raise QuantityError(
            "syntax",
            f"a text of {len(text)} characters; expected {_GRAMMAR}, at most "
            f"{MAX_QUANTITY_LENGTH} characters",
        )
    match = _QUANTITY.fullmatch(text)
    if match is None:
        raise QuantityError("syntax", f"not {_GRAMMAR}")
    number = float(match["number"])
    if match["unit"] is None:
        magnitude = number
    else:
        magnitude = _converted(number, match["unit"], unit, angle_explicit)
    if not math.isfinite(magnitude):
        raise QuantityError("value", f"not a finite number once converted to {unit}")
    return magnitude


@functools.cache
def si_scale(unit: str) -> float:
    """The factor from ``unit`` (the package's own unit text, never a file's) to SI base units."""
    return float(unit_registry().Quantity(1.0, unit).to_base_units().magnitude)


def _converted(number: float, text: str, unit: str, angle_explicit: bool) -> float:
    """``number`` in the unit ``text`` (already of the bounded grammar), converted to ``unit``."""
    factor = _factor(text, unit, angle_explicit)
    if factor is not None:
        return number * factor  # as pint converts: the magnitude times the units' factor
    pint = import_pint()
    try:  # an offset unit (degC): pint's own conversion of the number
        return float(unit_registry().Quantity(number, text.replace("^", "**")).to(unit).magnitude)
    except (pint.PintError, OverflowError, ValueError, TypeError):
        raise QuantityError("unit", f"a unit that cannot be converted to {unit}") from None


@functools.lru_cache(maxsize=1024)  # a catalogue gives 100 numbers in a dozen units
def check_unit(text: str) -> str:
    """``text`` if it is a unit of the bounded grammar (names, small integer powers, products and quotients).

    A unit given on a command line or in a file header is checked so before pint evaluates it: pint evaluates
    powers as arithmetic, and ``'9**9**9 s'`` would not finish. Raises :class:`QuantityError` otherwise.
    """
    if len(text) > MAX_QUANTITY_LENGTH:
        raise QuantityError("syntax", f"not a unit: longer than {MAX_QUANTITY_LENGTH} characters")
    quantity = _QUANTITY.fullmatch(text)
    if quantity is not None and quantity.group("unit"):  # '0 s', '-1 ms': a quantity, not a unit
        raise QuantityError(
            "syntax",
            f"not a unit: a unit name alone, without the number {quantity.group('number')!r} in front, "
            "e.g. 'ms', 'N*m', 'kg*m^2'",
        )
    if _UNIT_TEXT.fullmatch(text) is None:
        raise QuantityError(
            "syntax", "not a unit: names with powers of at most two digits, e.g. 'ms', 'N*m', 'kg*m^2'"
        )
    return text


def _factor(text: str, unit: str, angle_explicit: bool) -> float | None:
    """The factor from the unit ``text`` to ``unit``, once its dimension is checked (None for an offset unit)."""
    pint = import_pint()
    registry = unit_registry()
    try:
        given = registry.Quantity(1.0, text.replace("^", "**"))
        target = registry.Quantity(
            1.0, unit
        )  # the caller's unit: the package's own, or one check_unit passed
    except (pint.PintError, AttributeError, ValueError, TypeError, SyntaxError, KeyError):
        # KeyError: pint's own, for a unit to the power 0 ('m**0')
        raise QuantityError("unit", f"an unknown unit; expected {_GRAMMAR}") from None
    if given.dimensionality != target.dimensionality:
        raise QuantityError(
            "dimension",
            f"a unit of {_dimension(given)}, not {_dimension(target)} ({unit})",
            _dimension(given),
            _dimension(target),
        )
    if angle_explicit and _radian_power(given) != _radian_power(target):
        raise QuantityError(
            "angle", f"no angle unit; give an angle per time, e.g. '3000 rpm' or '314 {unit}'"
        )
    try:
        zero = registry.Quantity(0.0, text.replace("^", "**")).to(unit).magnitude
        factor = float(given.to(unit).magnitude)
    except (
        pint.PintError,
        OverflowError,
        ValueError,
        TypeError,
        KeyError,
    ):  # offset units (degC) in a product
        raise QuantityError("unit", f"a unit that cannot be converted to {unit}") from None
    return factor if zero == 0 else None


def _dimension(quantity: pint.Quantity) -> str:
    text = str(quantity.dimensionality)
    return "dimensionless" if text in ("", "dimensionless") else text


def _radian_power(quantity: Any) -> int:
    """The power of the angle (radian) in ``quantity``'s unit: 1 for ``rpm`` and ``rad/s``, 0 for ``Hz``."""
    return int(dict(quantity.to_root_units().unit_items()).get("radian", 0))
