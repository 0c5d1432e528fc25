"""The report's figures, drawn from saved results and returned as SVG text for the HTML report.

Each figure is drawn into ``figures/`` (PNG and/or SVG files) and its SVG text is returned for inlining in the
HTML report.
"""

from __future__ import annotations

import contextlib
import functools
import re
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, cast

import numpy as np

from ..errors import InvalidParameter
from ..plots import FigurePath
from ..plots.design_front import plot_design_front
from ..plots.impulse_directions import plot_impulse_directions
from ..plots.permissible_speeds import plot_permissible_speeds
from ..plots.phase_breakdown import plot_phase_breakdown
from ..plots.torque_speed import JointOperatingPoints, plot_torque_speed
from ..plots.velocity_sweep import plot_velocity_sweep
from ..plots.worst_pose import plot_worst_pose
from ..record.checked import ResultsDamaged
from ..record.run import ActuatorRunRecord, ArmRunRecord, RunRecord
from .wording import objective_unit

TORQUE_SPEED_FIELD = "recommended.torque_speed"
"""Where ``designs.json`` holds the recommended design's torque-speed data (duty-cycle studies only)."""


@contextlib.contextmanager
def _unique_svg_ids(name: str) -> Iterator[None]:
    """Salt Matplotlib's SVG ids with the figure's name, so inlined figures do not share ids.

    Matplotlib names SVG elements by hashes salted with ``svg.hashsalt``; a salt per figure keeps ids unique
    when several figures are inlined in one HTML page (and identical between runs).
    """
    import matplotlib  # lazy: matplotlib

    with matplotlib.rc_context({"svg.hashsalt": name}):
        yield


def _draw(directory: Path, name: str, formats: list[str], draw: Callable[[FigurePath], Path]) -> str:
    """Draw one figure once into its SVG (always: the report inlines it) and, if asked, its PNG."""
    directory.mkdir(parents=True, exist_ok=True)
    svg_path = directory / f"{name}.svg"
    with _unique_svg_ids(name):
        draw((svg_path, directory / f"{name}.png") if "png" in formats else svg_path)
    text = svg_path.read_text(encoding="utf-8")
    if "svg" not in formats:
        svg_path.unlink()
    # Inline: from the <svg> element on, without the metadata block (it only records the drawing time, which
    # would make otherwise identical reports differ).
    return re.sub(r"<metadata>.*?</metadata>\s*", "", text[text.index("<svg") :], count=1, flags=re.S)


def draw_figures(directory: Path, results: RunRecord, formats: list[str]) -> dict[str, str]:
    """Draw every figure of a report; returns inline SVG text by figure name."""
    if results["kind"] == "actuator":
        return _actuator_figures(directory, results, formats)
    return _arm_figures(directory, results, formats)


def _arm_figures(directory: Path, results: ArmRunRecord, formats: list[str]) -> dict[str, str]:
    svgs: dict[str, str] = {}
    samples = results["samples"]
    directions = np.asarray(samples["sample_directions"])
    config_index = np.asarray(samples["config_index"])
    pareto = results["pareto"]
    chosen = results["chosen"]
    names = pareto["objectives"]
    if len(pareto["points"]) >= 2:
        values = np.array([[p["objectives"][n] for n in names] for p in pareto["points"]])
        svgs["front"] = _draw(
            directory,
            "pareto_front",
            formats,
            lambda path: plot_design_front(
                path,
                names,
                [objective_unit(n) for n in names],
                values,
                [chosen["objectives"][n] for n in names[:2]],
                [results["recommended"]["objectives"][n] for n in names[:2]]
                if "recommended" in results
                else None,
            ),
        )
    # One surface, the recommended design's: the front's other designs differ from it in the table, not in where
    # around the arm the impulse is large.
    recommended = results.get("recommended") or chosen
    svgs["surface-0"] = _draw(
        directory,
        "impulse_directions",
        formats,
        functools.partial(
            plot_impulse_directions,
            directions=directions,
            config_index=config_index,
            impulses=np.asarray(recommended["impulses"]),
            title="impulse by contact direction [N*s]: " + str(recommended.get("source", "chosen design")),
        ),
    )
    shown = results.get("recommended")
    worst_case = shown.get("worst_case") if shown else None
    pose = None if worst_case is None else worst_case.get("pose")
    if worst_case is not None and pose is not None:
        svgs["worst_pose"] = _draw(
            directory,
            "worst_pose",
            formats,
            lambda path: plot_worst_pose(
                path,
                np.asarray(pose["joint_positions"]),
                np.asarray(pose["contact_position"]),
                np.asarray(pose["direction"]),
                f"worst case over the contact domain: {worst_case['domain']:.4g} N·s"
                + ("" if worst_case["certified"] else " (not certified)"),
            ),
        )
    contact = results.get("human_contact")
    if contact and contact["regions"]:
        rows = contact["regions"]
        svgs["permissible_speeds"] = _draw(
            directory,
            "permissible_speeds",
            formats,
            lambda path: plot_permissible_speeds(
                path,
                [r["region"] for r in rows],
                [r["slowest"] for r in rows],
                [r["median"] for r in rows],
                [r["fastest"] for r in rows],
                [r["iso_speed"] for r in rows],
                contact["approach_velocity"],
                f"ISO/TS 15066 body regions, {contact['samples']} contact samples",
            ),
        )
    joints = recommended_torque_speed(results)
    if joints is not None:
        svgs["torque_speed"] = _draw(
            directory, "torque_speed", formats, lambda path: plot_torque_speed(path, joints)
        )
    # The phases of each front design (of the recommended one without a front): where a front is flat, this
    # shows why.
    records = [(str(i), p) for i, p in enumerate(pareto["points"])] or [("recommended", recommended)]
    worst = [int(np.argmax(r["impulses"])) for _, r in records]
    svgs["phases"] = _draw(
        directory,
        "phase_breakdown",
        formats,
        lambda path: plot_phase_breakdown(
            path,
            [label for label, _ in records],
            [r["phases"]["initial"][w] for (_, r), w in zip(records, worst, strict=True)],
            [r["phases"]["sensing"][w] for (_, r), w in zip(records, worst, strict=True)],
            [r["phases"]["reaction"][w] for (_, r), w in zip(records, worst, strict=True)],
            "impulse by phase at each design's worst sample",
        ),
    )
    return svgs


def has_duty_cycle(results: ArmRunRecord) -> bool:
    """Whether the recommended design was sized by a motion: a duty cycle or a rated motion (its ``requirement``)."""
    from ..optimize.constraints import DUTY_REQUIREMENT, RATED_REQUIREMENT  # lazy: casadi

    recommended = results.get("recommended")
    return recommended is not None and recommended.get("requirement") in (DUTY_REQUIREMENT, RATED_REQUIREMENT)


def recommended_torque_speed(results: ArmRunRecord) -> list[JointOperatingPoints] | None:
    """The recommended design's saved torque-speed data, one entry per joint; None without a duty cycle.

    Each entry holds :class:`~collision_reflex.plots.torque_speed.JointOperatingPoints`'s fields.

    Raises
    ------
    ResultsDamaged
        The study has a duty cycle and :data:`TORQUE_SPEED_FIELD` is missing or empty, or an entry's arrays do
        not fit together (the message names the field). Its fields are checked when the record is read.
    """
    recommended = results.get("recommended")
    saved = recommended.get("torque_speed") if recommended else None
    if saved is None:
        if has_duty_cycle(results):
            raise ResultsDamaged(f"{TORQUE_SPEED_FIELD} is missing although the study has a duty cycle")
        return None
    if not saved:
        raise ResultsDamaged(f"{TORQUE_SPEED_FIELD} is not a list of joints' data")
    joints = []
    for index, entry in enumerate(saved):  # its fields checked when read (collision_reflex.record.read)
        try:
            joints.append(JointOperatingPoints(**cast("dict[str, Any]", entry)))
        except InvalidParameter as error:
            raise ResultsDamaged(f"{TORQUE_SPEED_FIELD}[{index}]: {error}") from None
    return joints


def _actuator_figures(directory: Path, results: ActuatorRunRecord, formats: list[str]) -> dict[str, str]:
    candidates = results["candidates"]
    svgs = {
        "sweep": _draw(
            directory,
            "velocity_sweep",
            formats,
            lambda path: plot_velocity_sweep(
                path,
                results["velocities"],
                {c["name"]: c["sweep"]["total"] for c in candidates},
                {c["name"]: (c["optimal_velocity"], c["minimum_impulse"]) for c in candidates},
            ),
        ),
        "phases": _draw(
            directory,
            "phase_breakdown",
            formats,
            lambda path: plot_phase_breakdown(
                path,
                [c["name"] for c in candidates],
                [c["impulse"]["initial"] for c in candidates],
                [c["impulse"]["sensing"] for c in candidates],
                [c["impulse"]["reaction"] for c in candidates],
                f"impulse by phase at v0 = {results['approach_velocity']:g} m/s",
            ),
        ),
    }
    return svgs
