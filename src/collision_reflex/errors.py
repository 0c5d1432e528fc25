"""Exceptions of collision-reflex.

Every error the package raises on purpose derives from :class:`CollisionReflexError`; errors about the value
of an input also derive from :class:`ValueError`. Messages say what was received, what was expected and what
to do, so that a command-line user sees one clear line instead of a traceback.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple


class CollisionReflexError(Exception):
    """Base class of every error raised on purpose by collision-reflex."""


class InvalidParameter(CollisionReflexError, ValueError):
    """A parameter has a value outside its allowed range (or is NaN, or of the wrong kind).

    Attributes
    ----------
    name: the parameter's name as the caller spelled it.
    value: the value received (an array is summarised in the message).
    allowed: a short phrase saying what is allowed, e.g. ``"a finite number > 0"``.
    """

    def __init__(self, name: str, value: Any, allowed: str, hint: str = "") -> None:
        self.name = name
        self.value = value
        self.allowed = allowed
        self.hint = hint
        message = f"{name} = {_describe(value)} is invalid: expected {allowed}"
        if hint:
            message += f"; {hint}"
        super().__init__(message)


def _describe(value: Any) -> str:
    """A short description of a received value, for error messages."""
    try:
        import numpy as np

        array = np.asarray(value)
        if array.ndim > 0 and array.size > 1 and array.dtype.kind in "fiu":
            bad = array[~np.isfinite(array) | (array <= 0)] if array.dtype.kind == "f" else array[array <= 0]
            shown = float(bad.flat[0] if bad.size else array.flat[0])
            return f"array of shape {array.shape} containing {shown!r}"
    except Exception:  # describing must never itself fail
        pass
    return repr(value)


class Violation(NamedTuple):
    """A constraint that a design does not meet, and by how much.

    Attributes
    ----------
    label: the NLP's label of the (worst) violated row, e.g. ``"peak torque of joint1 >= given requirement"``.
    amount: how far it is from being met, in ``unit`` (> 0).
    unit: the unit of ``amount``, e.g. ``"N*m"``; ``"-"`` for a row in the NLP's scaled units.
    """

    label: str
    amount: float
    unit: str = "-"


class SolverFailed(CollisionReflexError):
    """The optimiser did not converge, or found the problem infeasible.

    Attributes
    ----------
    status: IPOPT's return status of the last attempt (e.g. ``"Maximum_Iterations_Exceeded"``), or
        ``"Infeasible"`` when a feasibility solve confirmed that no design meets the constraints.
    stats: the solver statistics (iterations, timings, ...).
    violated: ``(label, amount[, unit])`` of the constraints that could not be met, worst first
        (:class:`Violation` after a feasibility solve, in physical units).
    problem: the problem that was solved, for inspection.
    attempts: ``(name, status, iterations, solve_time [s])`` of every IPOPT run, in order (see
        :func:`collision_reflex.optimize.solve.solve`).
    """

    def __init__(
        self,
        message: str,
        status: str,
        stats: dict,
        violated: Sequence[Violation | tuple[str, float]],
        problem: object = None,
        attempts: Sequence[tuple[str, str, int, float]] = (),
    ) -> None:
        self.status = status
        self.stats = stats
        self.violated = list(violated)
        self.problem = problem
        self.attempts = tuple(attempts)
        super().__init__(message)

    @property
    def confirmed_infeasible(self) -> bool:
        """Whether a feasibility solve confirmed that no design within the bounds meets the constraints."""
        return self.status == "Infeasible"

    def __reduce__(self) -> tuple:
        # The problem holds CasADi functions, which do not cross process boundaries; the rest does.
        return (type(self), (str(self), self.status, self.stats, self.violated, None, self.attempts))


@dataclass(frozen=True)
class StudyProblem:
    """One problem found in a study file.

    Attributes
    ----------
    file: the study file's path as given (``"<string>"`` for text not read from a file).
    line, column: 1-based position of the offending node (its key, or the nearest enclosing node that exists);
        0 for problems with the file itself (missing, unreadable).
    path: the field's path in the study, e.g. ``"actuators.joints.joint2.software_stiffness"``.
    found: a short description of what the file holds there.
    expected: what would be accepted, and where useful what to do.
    """

    file: str
    line: int
    column: int
    path: str
    found: str
    expected: str

    def __str__(self) -> str:
        where = f"{self.file}:{self.line}:{self.column}" if self.line > 0 else self.file  # 0: the file itself
        field = f" {self.path}:" if self.path else ""
        return f"{where}:{field} found {self.found}; expected {self.expected}"


class StudyFileError(CollisionReflexError, ValueError):
    """A study file cannot be used: every problem found, each located.

    Each problem has its file, line, field path, what was found and what was expected.

    Attributes
    ----------
    file: the study file's path as given.
    problems: the problems, in file order.
    """

    def __init__(self, file: str, problems: Sequence[StudyProblem]) -> None:
        self.file = file
        self.problems = tuple(sorted(problems, key=lambda p: (p.line, p.column, p.path)))
        if not self.problems:
            raise ValueError("StudyFileError needs at least one problem")
        if len(self.problems) == 1:
            message = str(self.problems[0])
        else:
            message = f"{len(self.problems)} problems in {file}:\n" + "\n".join(
                f"  {problem}" for problem in self.problems
            )
        super().__init__(message)


class FrameNotFound(CollisionReflexError, ValueError):
    """A contact frame (or joint) name does not exist in the robot model.

    Attributes
    ----------
    name: the name asked for.
    available: the names that do exist.
    kind: ``"frame"`` or ``"joint"``.
    """

    def __init__(self, name: str, available: Any, kind: str = "frame", robot: str = "") -> None:
        self.name = name
        self.available = tuple(available)
        self.kind = kind
        where = f" of {robot}" if robot else ""
        super().__init__(
            f"{kind} {name!r} not found in the model{where}; the {kind}s that exist are: "
            + ", ".join(self.available)
        )


class UrdfError(CollisionReflexError, ValueError):
    """A URDF file is missing or does not parse into a robot model.

    Attributes
    ----------
    path: the file.
    reason: the parser's own explanation (with its line number when it gives one).
    """

    def __init__(self, path: Any, reason: str) -> None:
        self.path = str(path)
        self.reason = reason
        super().__init__(f"cannot load URDF {self.path}: {reason}")


class UnknownMotor(CollisionReflexError, KeyError, ValueError):
    """A motor name that a catalogue does not hold.

    Attributes
    ----------
    name: the name asked for.
    available: the catalogue's names.
    path: the catalogue file.
    """

    def __init__(self, name: str, available: list[str], path: str) -> None:
        self.name = name
        self.available = available
        self.path = path
        super().__init__(name)

    def __str__(self) -> str:
        shown = ", ".join(self.available) if self.available else "none"
        return f"motor {self.name!r} is not in the catalogue {self.path} (it has: {shown}); `crx motors` lists it"


class CatalogueError(CollisionReflexError, ValueError):
    """A motor catalogue file that cannot be read: bad YAML, a missing field, a wrong type or value.

    Attributes
    ----------
    path: the file.
    line: 1-based line of the offending entry or field (None if unknown).
    field: the offending field, dotted from the top (e.g. ``"motors.M1.peak_torque"``), or "".
    reason: what is wrong and what to do.
    """

    def __init__(self, path: str, line: int | None, field: str, reason: str) -> None:
        self.path = path
        self.line = line
        self.field = field
        self.reason = reason
        where = f"{path}:{line}" if line is not None else path
        subject = f"{field}: " if field else ""
        super().__init__(f"{where}: {subject}{reason}")


class TraceError(CollisionReflexError, ValueError):
    """A force-time trace cannot be used: unreadable, malformed, or without a usable contact.

    Attributes
    ----------
    source: the file the trace came from (``""`` for an in-memory trace).
    trial: the trial's name within that file (``""`` if the file holds one trial).
    reason: what is wrong, in a short phrase (e.g. ``"no contact: ..."``).
    line: the file line (1-based) where the problem is, or ``None`` when it is not one line.
    """

    def __init__(self, source: str, trial: str, reason: str, line: int | None = None) -> None:
        self.source = source
        self.trial = trial
        self.reason = reason
        self.line = line
        where = source or "trace"
        if line is not None:
            where += f", line {line}"
        if trial:
            where += f" (trial {trial!r})"
        super().__init__(f"{where}: {reason}")


class TrajectoryError(TraceError):
    """A position trajectory (CSV file or arrays) cannot be used as a duty cycle.

    Attributes
    ----------
    source: the file (``""`` for arrays).
    line: the file line (1-based), or ``None`` for arrays (the reason then names the sample) or when the
        problem is not one line.
    reason: what is wrong and what to do.
    """

    def __init__(self, source: str, reason: str, line: int | None = None) -> None:
        super().__init__(source or "trajectory", "", reason, line)

    def __reduce__(self) -> tuple[Any, ...]:
        return (type(self), (self.source, self.reason, self.line))


class FitFailed(CollisionReflexError):
    """A least-squares fit did not converge or its result is not usable.

    Attributes
    ----------
    what: which fit (e.g. ``"one-shot fit"``).
    reason: the solver's message or the check that failed.
    """

    def __init__(self, what: str, reason: str) -> None:
        self.what = what
        self.reason = reason
        super().__init__(f"{what} failed: {reason}")


class StudyRunFailed(CollisionReflexError):
    """A study's design could not be found.

    The optimiser failed on a solve the study cannot do without (its optimum or a Pareto anchor). Plain data
    only, so that it crosses process boundaries.

    Attributes
    ----------
    what: which solve failed (``"optimum"``, ``"anchor: actuator_mass"``, ...).
    status: the solver's return status.
    """

    def __init__(self, message: str, what: str = "", status: str = "") -> None:
        self.what = what
        self.status = status
        super().__init__(message)

    def __reduce__(self) -> tuple[Any, ...]:
        return (type(self), (str(self), self.what, self.status))


class SimulationError(CollisionReflexError):
    """A time-domain simulation could not produce a result.

    Nothing was detected, the contact never ended, or the integrator failed; the message says what happened
    and what to change.
    """
