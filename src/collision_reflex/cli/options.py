"""Command-line options shared by every subcommand.

Each quantity is declared once, with its flag, unit, parser and range check; figures, tables and folders have
one flag each.

Rules, the same for every subcommand:

- A bare number is in the option's unit, shown in brackets in ``--help``: SI everywhere (m, kg, N, N/m,
  N*m/rad, m/s, s, Hz). An angle needs its unit (``30deg``, ``0.5rad``), as in study files: a bare angle could
  be degrees or radians. Any value may carry a unit instead (``60mm``, ``"2e7 N/m"``, ``10ms``), read by the
  study files' pint parser; a unit of another dimension is an error naming the option.
- A contact-level quantity (1D, along the contact direction) and a joint-level one are different quantities
  with different flags: ``--mech-stiffness`` [N/m] at the contact, ``--joint-mech-stiffness`` [N*m/rad] at a
  joint.
- ``--plot FILE`` for a figure, ``--csv FILE`` for a table, ``--out DIR`` for an output folder (``--out FILE``
  for the one file a command exports).
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any, Literal, NoReturn

import numpy as np

from ..vocabulary import DESIGN_CHOICES

UNITS_EPILOG = (
    "A bare number is in the unit shown in brackets (SI); an angle needs its unit (30deg, 0.5rad). Any physical "
    "value may carry a unit instead: 60mm, '2e7 N/m', 10ms, '1.3 N*m' (quote values with spaces)."
)


class Parser(argparse.ArgumentParser):
    """An ``ArgumentParser`` whose usage errors are one line on stderr (exit status 2)."""

    def error(self, message: str) -> NoReturn:
        """Print ``message`` as one line on stderr and exit with status 2."""
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def add_subcommand(
    subparsers: argparse._SubParsersAction, name: str, help: str, description: str, *, units: bool = True
) -> argparse.ArgumentParser:
    """A subcommand's parser; with ``units`` (a command with physical options), the unit rules in its ``--help``."""
    parser: argparse.ArgumentParser = subparsers.add_parser(
        name, help=help, description=description, epilog=UNITS_EPILOG if units else None
    )
    return parser


# --- quantities --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Quantity:
    """What an option measures: the unit of a bare number, and how to name it in messages.

    ``unit`` is a pint unit expression; ``shown`` is how ``--help`` writes it (``-`` for a pure number).
    ``bare``: a bare number is read in ``unit``; False (angles) refuses it: degrees and radians both read
    naturally.
    """

    unit: str
    what: str
    example: str
    metavar: str
    shown: str = ""
    bare: bool = True

    @property
    def label(self) -> str:
        """The unit as ``--help`` shows it."""
        return self.shown or self.unit


LENGTH = Quantity("m", "a length", "60mm", "M")
MASS = Quantity("kg", "a mass", "0.2 kg", "KG")
FORCE = Quantity("N", "a force", "3 N", "N")
TORQUE = Quantity("N*m", "a torque", "1.3 N*m", "N*M")
LINEAR_STIFFNESS = Quantity("N/m", "a linear stiffness", "1000 N/m", "N/M")
ROTARY_STIFFNESS = Quantity("N*m/rad", "a rotary stiffness", "250 N*m/rad", "N*M/RAD")
VELOCITY = Quantity("m/s", "a velocity", "0.5 m/s", "M/S")
ACCELERATION = Quantity("m/s^2", "an acceleration", "20 m/s^2", "M/S2")
DAMPING = Quantity("N*s/m", "a damping", "5 N*s/m", "N*S/M")
TIME = Quantity("s", "a time", "10ms", "S")
FREQUENCY = Quantity("Hz", "a frequency", "1 kHz", "HZ")
ANGLE = Quantity("deg", "an angle", "45deg", "DEG", shown="deg/rad", bare=False)
NUMBER = Quantity("", "a pure number", "0.5", "X", shown="-")

Bound = Literal["positive", "non-negative", "any"]
Form = Literal["one", "range", "list"]
_BOUND_TEXT = {"positive": "> 0", "non-negative": ">= 0", "any": ""}
_RANGE_HINT = "START:STOP:N (N log-spaced values) or v1,v2,..."


@dataclass(frozen=True)
class QuantityParser:
    """Text to a float in ``quantity.unit`` (``form="one"``) or to an array.

    ``"range"`` is ``START:STOP:N`` (N log-spaced values, both ends included) or ``v1,v2,...``; ``"list"`` is
    ``v1,v2,...`` only.
    """

    quantity: Quantity
    bound: Bound = "positive"
    allow_inf: bool = False
    allow_none: bool = False
    form: Form = "one"

    def __call__(self, text: str) -> Any:
        """Parse ``text``; a bad value raises ``argparse.ArgumentTypeError`` with the expected unit."""
        if self.form == "one":
            if self.allow_none and text.strip().lower() == "none":
                return None
            return self.one(text)
        if self.form == "range" and ":" in text:
            return self._log_range(text)
        parts = [part.strip() for part in text.split(",") if part.strip()]
        if not parts:
            raise argparse.ArgumentTypeError(f"{text!r} is not a comma-separated list")
        _same_unit_rule(text, parts)
        if not self.quantity.bare and any(_is_number(part) for part in parts):
            raise argparse.ArgumentTypeError(
                f"{text!r} has no unit: {self.quantity.what} needs one on every value, e.g. "
                + ",".join(f"{part}deg" for part in parts[:2])
            )
        if self.form == "list":
            try:
                return np.array([self.one(part) for part in parts])
            except argparse.ArgumentTypeError:
                raise argparse.ArgumentTypeError(
                    f"{text!r}: every value must be a finite number {_BOUND_TEXT[self.bound]}"
                ) from None
        return np.array([self.one(part) for part in parts])

    def one(self, text: str) -> float:
        """One value, checked against the bound."""
        stripped = text.strip()
        if self.allow_inf and stripped.lower() in ("inf", "infinity"):
            return math.inf
        try:
            value = float(stripped)
        except ValueError:
            value = self._with_unit(stripped)
        else:
            if not self.quantity.bare:
                raise argparse.ArgumentTypeError(
                    f"{text!r} has no unit: {self.quantity.what} needs one, e.g. {stripped}deg or {stripped}rad"
                )
        if not math.isfinite(value) or not self._in_bounds(value):
            raise argparse.ArgumentTypeError(f"{text!r} is not a finite number {_BOUND_TEXT[self.bound]}")
        return value

    def _in_bounds(self, value: float) -> bool:
        return {"positive": value > 0, "non-negative": value >= 0, "any": True}[self.bound]

    def _with_unit(self, text: str) -> float:
        from pydantic_core import PydanticCustomError

        from ..study.quantities import to_si  # lazy: pydantic and yaml (the study schema)

        q = self.quantity
        try:
            return to_si(text, q.unit, q.what, q.example)
        except PydanticCustomError as error:
            expected = f"{q.what} in {q.label}, e.g. {q.example!r} (a bare number is in {q.label})"
            if error.type == "quantity_dimension":
                found = (error.context or {}).get("found_dimension", "another dimension")
                raise argparse.ArgumentTypeError(f"{text!r} is {found}: expected {expected}") from None
            raise argparse.ArgumentTypeError(f"{text!r} is not a quantity: expected {expected}") from None

    def _log_range(self, text: str) -> np.ndarray:
        try:
            start_text, stop_text, count_text = text.split(":")
            count = int(count_text)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"{text!r} is neither START:STOP:N nor a comma-separated list of numbers > 0"
            ) from None
        _same_unit_rule(text, [start_text, stop_text])
        start, stop = self.one(start_text), self.one(stop_text)
        if count < 1:
            raise argparse.ArgumentTypeError(f"{text!r}: N must be at least 1")
        if count > 1 and stop <= start:
            raise argparse.ArgumentTypeError(f"{text!r}: STOP must be greater than START")
        return np.geomspace(start, stop, count)


def joint_position(text: str) -> float:
    """A joint position given on the command line, in SI: an angle in rad or (prismatic) a length in m.

    It needs its unit (``30deg``, ``0.5rad``, ``0.1m``), as in study files.
    """
    from pydantic_core import PydanticCustomError

    from ..study.quantities import joint_position_si  # lazy: pydantic and yaml (the study schema)

    try:
        return joint_position_si(text.strip())[0]
    except PydanticCustomError as error:
        raise argparse.ArgumentTypeError(f"{text!r}: expected {error.message()}") from None


def _same_unit_rule(text: str, parts: Sequence[str]) -> None:
    """Refuse ``10,60,100mm``: a unit on only some values is likely meant for all of them."""
    bare = [_is_number(part) for part in parts]
    if any(bare) and not all(bare):
        raise argparse.ArgumentTypeError(f"{text!r}: give a unit on every value or on none")


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


# --- options -----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Option:
    """A physical option, declared once: flag, destination, quantity, description and range."""

    flag: str
    dest: str
    quantity: Quantity
    what: str
    bound: Bound = "positive"
    allow_inf: bool = False
    allow_none: bool = False
    form: Form = "one"
    hint: str = ""

    def add(
        self,
        parser: argparse.ArgumentParser,
        default: Any = None,
        *,
        note: str = "",
        shown: str | None = None,
        bound: Bound | None = None,
        nargs: int | str | None = None,
        required: bool = False,
    ) -> None:
        """Add the option to ``parser``.

        ``default`` is a value in the option's unit (or text, parsed like the command line); ``shown`` is how
        the help writes it (default: the value itself); ``note`` follows the unit in the help; a ``required``
        option must be given.
        """
        parse = QuantityParser(self.quantity, bound or self.bound, self.allow_inf, self.allow_none, self.form)
        text = f"{self.what} [{self.quantity.label}]"
        text += "".join(f"; {part}" for part in (self.hint, note) if part)
        if shown is None and default is not None:
            shown = default if isinstance(default, str) else f"{default:g}"
        if shown is not None:
            text += f" (default {shown})"
        metavar: str | tuple[str, ...] = self.quantity.metavar
        if self.form != "one":
            metavar = "RANGE" if self.form == "range" else "LIST"
        if isinstance(nargs, int):
            metavar = tuple("XYZ"[:nargs])
        extra: dict[str, Any] = {} if nargs is None else {"nargs": nargs}
        if required:
            extra["required"] = True
        parser.add_argument(
            self.flag,
            dest=self.dest,
            type=parse,
            default=default,
            metavar=metavar,
            help=text.replace("%", "%%"),
            **extra,
        )

    def values(
        self, flag: str, dest: str, what: str, *, form: Form = "range", hint: str = _RANGE_HINT
    ) -> Option:
        """The option of many values of the same quantity and range: a ``"range"`` (the default) or a ``"list"``."""
        return replace(self, flag=flag, dest=dest, what=what, form=form, hint=hint)


# Contact-level quantities (1D, along the contact direction): the paper's symbols as destinations.
FINGER_MASS = Option("--finger-mass", "m_f", MASS, "finger (sprung) mass m_f at the contact")
ROBOT_MASS = Option("--robot-mass", "m_r", MASS, "robot (unsprung) mass m_r at the contact")
RATED_PAYLOAD = Option(
    "--payload", "payload", MASS, "the robot's rated payload (its datasheet's)", bound="non-negative"
)
MECH_STIFFNESS = Option(
    "--mech-stiffness", "k_m", LINEAR_STIFFNESS, "mechanical stiffness k_m at the contact"
)
MECH_STIFFNESSES = MECH_STIFFNESS.values(
    "--mech-stiffnesses", "k_m_values", "mechanical stiffnesses k_m at the contact"
)
SOFT_STIFFNESS = Option(
    "--soft-stiffness",
    "k_s",
    LINEAR_STIFFNESS,
    "software (controller) stiffness k_s at the contact",
    allow_inf=True,
    hint="'inf' for a rigid one",
)
STIFFNESS = Option(
    "--stiffness", "k", LINEAR_STIFFNESS, "lumped sensing stiffness k at the contact (k_m and k_s in series)"
)
TASK_STIFFNESS = Option(
    "--task-stiffness",
    "task_stiffness",
    LINEAR_STIFFNESS,
    "Cartesian controller stiffness",
    allow_none=True,
    hint="'none' for none",
)
CONTACT_STIFFNESS = Option(
    "--contact-stiffness",
    "contact_stiffness",
    LINEAR_STIFFNESS,
    "wall contact stiffness",
    allow_inf=True,
    hint="'inf' for a rigid, plastic wall",
)
THRESHOLD = Option("--threshold", "F_s", FORCE, "force threshold F_s", hint="the contact force at detection")
POSITION_ERROR = Option(
    "--position-error", "e_th", LENGTH, "position-error threshold e_th at the contact", hint="F_s = k e_th"
)
ACCEL = Option(
    "--accel", "a", ACCELERATION, "reaction acceleration a of the robot mass away from the contact"
)
FORCE_LIMIT = Option(
    "--force-limit",
    "F_a",
    FORCE,
    "actuator force limit F_a at the contact",
    hint="the reaction is a = F_a / m_r",
)
APPROACH_VELOCITY = Option("--velocity", "v0", VELOCITY, "approach (pre-impact) velocity v0")
# A human body region (ISO/TS 15066 Annex A): a spring with an effective mass and a force limit.
REGION_STIFFNESS = Option(
    "--region-stiffness", "region_stiffness", LINEAR_STIFFNESS, "the body region's spring constant k_c"
)
REGION_MASS = Option(
    "--region-mass",
    "region_mass",
    MASS,
    "the body region's effective mass m_H",
    allow_inf=True,
    hint="'inf' for a region held against something",
)
TRANSIENT_FORCE = Option(
    "--transient-force", "transient_force", FORCE, "the body region's permissible transient contact force F_T"
)
APPROACH_VELOCITIES = APPROACH_VELOCITY.values("--velocities", "velocities", "approach velocities")
TRACE_VELOCITY = Option(
    "--trace-velocity", "trace_velocity", VELOCITY, "approach velocity of the --trace-plot simulation"
)
ROBOT_VELOCITY = Option(
    "--robot-velocity",
    "v_r",
    VELOCITY,
    "robot-mass velocity v_r toward the contact at detection",
    bound="non-negative",
)
SOFT_DAMPING = Option("--soft-damping", "d_s", DAMPING, "software damping d_s", bound="non-negative")
COULOMB = Option("--coulomb", "coulomb", FORCE, "Coulomb friction on the robot mass", bound="non-negative")
VISCOUS = Option("--viscous", "viscous", DAMPING, "viscous friction on the robot mass", bound="non-negative")
BACKLASH = Option("--backlash", "backlash", LENGTH, "backlash", bound="non-negative")
BACKLASHES = BACKLASH.values("--backlashes", "backlashes", "backlash values", form="list", hint="b1,b2,...")
DELAY = Option("--delay", "delay", TIME, "sensing delay", bound="non-negative")
DELAYS = DELAY.values("--delays", "delays", "sensing delays", form="list", hint="d1,d2,...")
RESTITUTION = Option("--restitution", "restitution", NUMBER, "coefficient of restitution", hint="in (0, 1]")
TOLERANCE = Option("--tolerance", "tolerance", NUMBER, "relative difference counted as parting")
CONTROL_RATE = Option("--control-rate", "control_rate", FREQUENCY, "rate of the sampled control")
BANDWIDTH = Option("--bandwidth", "bandwidth", FREQUENCY, "cutoff of the sensor's 2nd-order low-pass filter")
NOISE_SIGMAS = Option(
    "--threshold-sigmas",
    "n_sigma",
    NUMBER,
    "contact threshold above the noise floor",
    hint="in noise standard deviations",
)
LEVER = Option("--lever", "lever", LENGTH, "joint axis to contact distance L")

# Joint- and actuator-level quantities: spelled-out names in joint units.
STATOR_DIAMETER = Option("--stator-diameter", "stator_diameter", LENGTH, "motor stator outer diameter")
STATOR_DIAMETERS = STATOR_DIAMETER.values(
    "--stator-diameters", "stator_diameters", "motor stator outer diameters"
)
STACK_LENGTH = Option("--stack-length", "stack_length", LENGTH, "motor stack length")
TORQUE_REQUIRED = Option("--torque", "torque", TORQUE, "output torque requirement tau_req")
GEAR_RATIO = Option("--gear-ratio", "gear_ratio", NUMBER, "gear ratio N", hint=">= 1")
JOINT_MECH_STIFFNESS = Option(
    "--joint-mech-stiffness", "mechanical_stiffness", ROTARY_STIFFNESS, "joint mechanical stiffness"
)
JOINT_SOFT_STIFFNESS = Option(
    "--joint-soft-stiffness",
    "software_stiffness",
    ROTARY_STIFFNESS,
    "joint software stiffness",
    allow_inf=True,
    hint="'inf' for none",
)
CONTACT_OFFSET = Option("--offset", "offset", LENGTH, "contact point in the contact frame", bound="any")
SECOND_JOINT_ANGLES = Option(
    "--q2-values",
    "q2_values",
    ANGLE,
    "second joint angles of the grid's first row",
    bound="non-negative",
    form="list",
    hint="a1,a2,..., each with its unit (45deg, 0.8rad)",
)


# --- files and folders -------------------------------------------------------------------------------------


def add_plot(
    parser: argparse.ArgumentParser,
    default: str | None = None,
    *,
    what: str = "the figure",
    flag: str = "--plot",
) -> None:
    """``--plot FILE``: a figure (.png, .svg or .pdf)."""
    shown = f" (default {default})" if default else ""
    parser.add_argument(
        flag,
        dest=flag.lstrip("-").replace("-", "_"),
        default=default,
        metavar="FILE",
        help=f"draw {what} to FILE (.png, .svg or .pdf){shown}",
    )


def add_csv(
    parser: argparse.ArgumentParser,
    default: str | None = None,
    *,
    what: str = "the numbers",
) -> None:
    """``--csv FILE``: a table."""
    shown = f" (default {default})" if default else ""
    parser.add_argument("--csv", default=default, metavar="FILE", help=f"write {what} to FILE (CSV){shown}")


def add_design(parser: argparse.ArgumentParser) -> None:
    """``--design``: one design of a run folder, by Pareto number or by word (:data:`DESIGN_CHOICES`)."""
    parser.add_argument(
        "--design",
        default="recommended",
        metavar="N|" + "|".join(DESIGN_CHOICES),
        help="the design built from catalogue parts, the Pareto design N (the point column of pareto.csv), the "
        "recommended design, or the chosen one (the single-objective optimum); default recommended",
    )


def add_out_dir(parser: argparse.ArgumentParser, *, what: str, shown: str = "") -> None:
    """``--out DIR``: an output folder."""
    default = f" (default {shown})" if shown else ""
    parser.add_argument("--out", default=None, metavar="DIR", help=f"write {what} to the folder DIR{default}")


def add_out_file(parser: argparse.ArgumentParser, *, what: str) -> None:
    """``--out FILE``: the one file a command exports (required)."""
    parser.add_argument("--out", required=True, metavar="FILE", help=f"write {what} to FILE")


def add_catalogue(parser: argparse.ArgumentParser) -> None:
    """``--catalogue FILE``: a motor catalogue."""
    parser.add_argument(
        "--catalogue", default=None, metavar="FILE", help="a motor catalogue YAML file (default: packaged)"
    )
