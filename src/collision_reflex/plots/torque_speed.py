"""Torque–speed figure per joint: the duty cycle's motor operating points over the motor's envelope.

The figure is drawn as motor sizing tools draw it: the magnitudes ``|speed|`` and ``|torque|`` in the first
quadrant, because the envelope of a motor and drive is symmetric in the sign of torque and speed (it
motors and brakes alike in both directions), so folding the four quadrants onto one shows every point
against the same limits and doubles the resolution. Torques and speeds are motor-side (joint torque divided
by the gear ratio, joint speed times the gear ratio). Speed is in rad/s on the bottom axis and in rpm on the
top axis. Each subplot's title states the joint's margins, limits and RMS torque; one legend for the figure
(in an empty grid cell, else below the grid) names the kinds of lines and points, which every subplot shares.
The grid is laid out from the sizes of those texts (:mod:`.grid_layout`), not by measuring a drawing, and the
figure is saved whole. Points that fall on one spot (a ten-thousandth of each axis range) are drawn once.

The envelope is the rectangle the catalogue can state: the peak torque up to the maximum speed. The
continuous (thermal) torque bounds the cycle's RMS torque, not single points, so it is drawn as a line and
the RMS torque is compared with it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .._validate import non_negative, positive
from ..errors import InvalidParameter
from . import FigurePath, figure_paths, margin_text, new_figure, save_figure
from .grid_layout import extent, lay_out_grid

RAD_PER_S_TO_RPM = 60.0 / (2.0 * math.pi)
INSIDE_COLOUR = "tab:blue"
APPROACH_COLOUR = "tab:green"
WARNING_COLOUR = "tab:red"
COLUMNS = 3
CELL = (4.6, 3.9)  # in: width and height of one joint's subplot with its labels and title
RPM_LABEL = "motor speed [rpm]"
RPM_LABEL_SIZE = 8
ENVELOPE_LABEL = "peak torque, max speed"
SPOT = 1e-4  # of an axis range (a twentieth of a pixel at 150 dpi): points on one spot are drawn once


@dataclass(frozen=True)
class JointOperatingPoints:
    """One joint's motor-side operating points and its motor's envelope.

    Parameters
    ----------
    joint : str
        The joint's name (the subplot's title).
    speed : array_like
        Motor speed at each sample of the duty cycle [rad/s], signed; may be empty (no duty cycle).
    torque : array_like
        Motor torque at each sample of the duty cycle [N*m], signed, motor-side (joint torque / gear
        ratio); same length as ``speed``.
    approach_speed : array_like, optional
        Motor speeds of the approach to contact [rad/s], signed; may be empty.
    peak_torque : float, optional
        The motor's peak torque [N*m]; None when unknown (not drawn).
    continuous_torque : float, optional
        The motor's continuous (thermal) torque [N*m]; None when unknown (not drawn).
    max_speed : float, optional
        The motor's maximum speed [rad/s]; None when unknown (not drawn).
    rms_torque : float, optional
        The RMS motor torque over the cycle [N*m]; None when not computed.
    """

    joint: str
    speed: np.ndarray
    torque: np.ndarray
    approach_speed: np.ndarray = field(default_factory=lambda: np.zeros(0))
    peak_torque: float | None = None
    continuous_torque: float | None = None
    max_speed: float | None = None
    rms_torque: float | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.joint, str) or not self.joint:
            raise InvalidParameter("joint", self.joint, "a non-empty joint name")
        for name in ("speed", "torque", "approach_speed"):
            object.__setattr__(self, name, self._finite_array(name, getattr(self, name)))
        if self.speed.size != self.torque.size:
            raise InvalidParameter(
                f"{self.joint}: torque",
                f"{self.torque.size} samples",
                f"as many samples as speed ({self.speed.size})",
            )
        for name in ("peak_torque", "continuous_torque", "max_speed", "rms_torque"):
            value = getattr(self, name)
            if value is None:
                continue
            if np.ndim(value) != 0:
                raise InvalidParameter(f"{self.joint}: {name}", value, "a single number or None")
            # A limit of zero is no motor; a zero RMS torque is an unloaded joint.
            check = non_negative if name == "rms_torque" else positive
            object.__setattr__(self, name, float(check(f"{self.joint}: {name}", value)))

    def _finite_array(self, name: str, value: Any) -> np.ndarray:
        """``value`` as a 1-D float array of finite numbers, else raise naming the joint and field."""
        try:
            array = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            raise InvalidParameter(f"{self.joint}: {name}", value, "a 1-D array of numbers") from None
        if array.ndim != 1:
            raise InvalidParameter(f"{self.joint}: {name}", f"shape {array.shape}", "a 1-D array")
        if not np.all(np.isfinite(array)):
            raise InvalidParameter(f"{self.joint}: {name}", value, "finite numbers (no NaN or inf)")
        return array


def outside_envelope(
    speed: np.ndarray, torque: np.ndarray, peak_torque: float | None, max_speed: float | None
) -> np.ndarray:
    """Which operating points lie outside the motor's envelope (a point on a limit is inside).

    Parameters
    ----------
    speed : array_like
        Motor speeds [rad/s], signed.
    torque : array_like
        Motor torques [N*m], signed, same length as ``speed``.
    peak_torque : float or None
        Peak torque [N*m]; None when unknown (no point is outside it).
    max_speed : float or None
        Maximum speed [rad/s]; None when unknown (no point is outside it).

    Returns
    -------
    numpy.ndarray
        Boolean mask, True where ``|torque| > peak_torque`` or ``|speed| > max_speed``.
    """
    speed = np.abs(np.asarray(speed, dtype=float))
    torque = np.abs(np.asarray(torque, dtype=float))
    outside = np.zeros(speed.shape, dtype=bool)
    if peak_torque is not None:
        outside |= torque > peak_torque
    if max_speed is not None:
        outside |= speed > max_speed
    return outside


def margins(point: JointOperatingPoints) -> dict[str, float | None]:
    """Peak, RMS and speed margins as fractions (``limit / required - 1``), None when either is absent.

    The speed margin covers the duty cycle's and the approach's speeds. A required value of zero with a
    known limit has an infinite margin.
    """
    speeds = np.abs(np.concatenate([point.speed, point.approach_speed]))
    required = {
        "peak": float(np.max(np.abs(point.torque))) if point.torque.size else None,
        "RMS": point.rms_torque,
        "speed": float(np.max(speeds)) if speeds.size else None,
    }
    limits = {"peak": point.peak_torque, "RMS": point.continuous_torque, "speed": point.max_speed}
    out: dict[str, float | None] = {}
    for name, need in required.items():
        limit = limits[name]
        if need is None or limit is None:
            out[name] = None
        else:
            out[name] = limit / need - 1 if need > 0 else math.inf
    return out


def plot_torque_speed(path: FigurePath, joints: Sequence[JointOperatingPoints]) -> Path:
    """Draw one torque–speed subplot per joint (a grid of up to 3 columns) and save it.

    Parameters
    ----------
    path : FigurePath
        The figure file (.png, .svg or .pdf), or a tuple of files of the same figure.
    joints : sequence of JointOperatingPoints
        One entry per joint, in the order drawn.

    Returns
    -------
    pathlib.Path
        The written file.
    """
    figure_paths(path)
    joints = list(joints)
    if not joints:
        raise InvalidParameter("joints", joints, "at least one joint's operating points")
    for index, point in enumerate(joints):
        if not isinstance(point, JointOperatingPoints):
            raise InvalidParameter(f"joints[{index}]", point, "a JointOperatingPoints")
    columns = min(COLUMNS, len(joints))
    rows = math.ceil(len(joints) / columns)
    fig, axes = new_figure(rows, columns, figsize=(CELL[0] * columns, CELL[1] * rows), squeeze=False)
    # One legend for the figure: every subplot draws the same kinds of lines and points, and each joint's
    # numbers are in its title. Placed outside the data (an empty grid cell, else below the grid), so it
    # never hides a point and needs no search for a free place.
    legend: dict[str, Any] = {}
    rpm_axis = _rpm_axis_offsets(fig)
    for ax, point in zip(axes.flat, joints, strict=False):
        _draw_joint(ax, point, legend, rpm_axis[2])
    empty = list(axes.flat)[len(joints) :]
    for ax in empty:
        ax.set_visible(False)
    suptitle = fig.suptitle(
        "Motor operating points over the motor envelope (|speed|, |torque|, motor side)", fontsize=11
    )
    shared = _shared_legend(fig, legend, empty[0] if empty else None, columns) if legend else None
    below = shared if shared is not None and not empty else None
    drawn = list(axes.flat)[: len(joints)]
    lay_out_grid(fig, drawn, (rows, columns), CELL, rpm_axis[2], suptitle, below)
    for ax in drawn:
        _rpm_axis(ax, rpm_axis)
    # Everything is inside the figure: saved whole, without measuring its tight bounding box.
    return save_figure(fig, path, crop=False)


def _shared_legend(fig: Any, legend: dict[str, Any], empty_cell: Any | None, columns: int) -> Any:
    """The figure's legend: centred in ``empty_cell`` (an unused subplot), else below the grid of ``columns``.

    Below the grid it has two legend columns per subplot column; the layout places it.
    """
    if empty_cell is not None:
        where = {"loc": "center", "bbox_to_anchor": (0.5, 0.5), "bbox_transform": empty_cell.transAxes}
    else:
        where = {"loc": "lower center", "ncols": min(2 * columns, len(legend))}
    return fig.legend(list(legend.values()), list(legend.keys()), fontsize=9, **where)


def _draw_joint(ax: Any, point: JointOperatingPoints, legend: dict[str, Any], title_pad: float) -> None:
    """One joint's subplot: envelope lines, cycle points, approach speeds, RMS torque; title with the numbers.

    Each kind of artist drawn is added to ``legend`` (label to artist) for the figure's shared legend. The
    title is ``title_pad`` [pt] above the subplot, over the rpm axis (drawn after the layout).
    """
    speed, torque = np.abs(point.speed), np.abs(point.torque)
    approach = np.abs(point.approach_speed)
    # Room above the largest point or limit; a unit range when there is nothing to scale by.
    x_top = 1.15 * max([*speed, *approach, point.max_speed or 0.0]) or 1.0
    y_top = (
        1.15
        * max([*torque, point.peak_torque or 0.0, point.continuous_torque or 0.0, point.rms_torque or 0.0])
        or 1.0
    )
    _draw_envelope(ax, point, legend)
    outside = outside_envelope(speed, torque, point.peak_torque, point.max_speed)
    for selected, size, colour, label in (
        (~outside, 4, INSIDE_COLOUR, "duty cycle"),
        (outside, 6, WARNING_COLOUR, "outside the envelope"),
    ):
        if np.any(selected):
            x, y = _one_per_spot(speed[selected], torque[selected], x_top, y_top)
            (legend[label],) = ax.plot(x, y, ".", ms=size, color=colour)
    # The approach runs at constant speed: its torque is drawn at zero, on the speed axis (not clipped).
    fast = outside_envelope(approach, np.zeros_like(approach), None, point.max_speed)
    for selected, colour, label in (
        (~fast, APPROACH_COLOUR, "approach"),
        (fast, WARNING_COLOUR, "approach, too fast"),
    ):
        if np.any(selected):
            x, y = _one_per_spot(approach[selected], np.zeros(int(np.sum(selected))), x_top, y_top)
            (legend[label],) = ax.plot(x, y, "^", ms=7, color=colour, clip_on=False)
    if point.rms_torque is not None:
        too_hot = point.continuous_torque is not None and point.rms_torque > point.continuous_torque
        legend["RMS torque above continuous" if too_hot else "RMS torque"] = ax.axhline(
            point.rms_torque, color=WARNING_COLOUR if too_hot else "black", ls=":", lw=1.2
        )
    ax.set_xlim(0.0, x_top)
    ax.set_ylim(0.0, y_top)
    ax.set_xlabel("motor speed |ω| [rad/s]")
    ax.set_ylabel("motor torque |τ| = joint torque / N [N·m]", fontsize=8)
    short = any(value is not None and value < 0 for value in margins(point).values())
    ax.set_title(
        f"{point.joint}\n{_margin_text(point)}\n{_limits_text(point)}",
        fontsize=8,
        color=WARNING_COLOUR if short else "black",
        y=1.0,
        pad=title_pad,
    )
    ax.grid(True, alpha=0.3)


def _one_per_spot(x: np.ndarray, y: np.ndarray, x_top: float, y_top: float) -> tuple[np.ndarray, np.ndarray]:
    """The points ``(x, y)`` with those on the same spot (a ``SPOT`` of each axis range) drawn once, in order.

    A cycle dwells and an approach repeats its speed, so many markers fall on one another: drawn again they
    look the same but cost time, most in the SVG (an element each). A spot is far below a pixel.
    """
    cells = np.stack([np.round(x / (SPOT * x_top)), np.round(y / (SPOT * y_top))])
    first = np.sort(np.unique(cells, axis=1, return_index=True)[1])
    return x[first], y[first]


def _rpm_axis(ax: Any, offsets: tuple[float, float, float]) -> None:
    """The rpm scale on top of a laid-out subplot: ticks at round rpm, their labels and the axis's label.

    Drawn as a tick-mark line and texts, which show what a secondary axis shows at a fraction of its cost (an
    axis is a whole subplot of its own, its tick labels measured at every drawing). As many ticks as
    matplotlib's own axis would fit: one per three tick-label font sizes of the subplot's width. ``offsets``
    are from :func:`_rpm_axis_offsets`.
    """
    from matplotlib import rcParams
    from matplotlib.font_manager import FontProperties
    from matplotlib.markers import TICKUP
    from matplotlib.ticker import MaxNLocator
    from matplotlib.transforms import offset_copy

    fig = ax.get_figure()
    font = FontProperties(size=rcParams["xtick.labelsize"]).get_size_in_points()
    width = ax.get_position().width * fig.get_size_inches()[0] * 72
    top = ax.get_xlim()[1] * RAD_PER_S_TO_RPM
    rpm = MaxNLocator(nbins=max(1, int(width // (3 * font))), steps=[1, 2, 2.5, 5, 10]).tick_values(0.0, top)
    rpm = rpm[(rpm >= -1e-9 * top) & (rpm <= (1 + 1e-9) * top)]  # those on the axis, as an axis keeps them
    along = ax.get_xaxis_transform()  # x in rad/s, y in axes fractions: the top edge is y = 1
    colour = rcParams["xtick.color"]
    tick, label, _ = offsets
    ax.plot(
        rpm / RAD_PER_S_TO_RPM,
        np.ones_like(rpm),
        ls="none",
        marker=TICKUP,
        ms=rcParams["xtick.major.size"],
        mew=rcParams["xtick.major.width"],
        color=colour,
        transform=along,
        clip_on=False,
    )
    above = offset_copy(along, fig=fig, y=tick, units="points")
    for value in rpm:
        # %g: every label is its whole number (no offset or multiplier written elsewhere).
        ax.text(
            value / RAD_PER_S_TO_RPM,
            1.0,
            f"{value:g}",
            transform=above,
            ha="center",
            va="bottom",
            fontsize=font,
            color=colour,
        )
    ax.text(
        0.5,
        1.0,
        RPM_LABEL,
        transform=offset_copy(ax.transAxes, fig=fig, y=label, units="points"),
        ha="center",
        va="bottom",
        fontsize=RPM_LABEL_SIZE,
    )


def _rpm_axis_offsets(fig: Any) -> tuple[float, float, float]:
    """Heights [pt] above a subplot of the bottoms of the rpm tick labels, the rpm axis label and the title.

    Spaced as matplotlib spaces an axis at the top: tick, pad, tick labels, label pad, label, title pad.
    """
    from matplotlib import rcParams

    tick = rcParams["xtick.major.size"] + rcParams["xtick.major.pad"]
    label = tick + extent(fig, "0123456789", rcParams["xtick.labelsize"])[1] + rcParams["axes.labelpad"]
    return tick, label, label + extent(fig, RPM_LABEL, RPM_LABEL_SIZE)[1] + rcParams["axes.titlepad"]


def _draw_envelope(ax: Any, point: JointOperatingPoints, legend: dict[str, Any]) -> None:
    """Peak torque (up to the maximum speed), continuous torque and maximum speed, those that are known."""
    x_end = point.max_speed if point.max_speed is not None else 1.0
    transform = ax.transData if point.max_speed is not None else ax.get_yaxis_transform()
    for value, name, style in (
        (point.peak_torque, ENVELOPE_LABEL, "-"),
        (point.continuous_torque, "continuous torque", "--"),
    ):
        if value is not None:
            (legend[name],) = ax.plot(
                [0.0, x_end], [value, value], style, color="dimgray", lw=1.4, transform=transform
            )
    if point.peak_torque is not None:
        # The region the motor can reach, lightly shaded.
        ax.fill_between([0.0, x_end], 0.0, point.peak_torque, color="0.92", transform=transform, zorder=0)
    if point.max_speed is not None:
        legend[ENVELOPE_LABEL] = ax.axvline(point.max_speed, color="dimgray", lw=1.4)


def _limits_text(point: JointOperatingPoints) -> str:
    """The joint's limits and RMS torque in two lines; "unknown" for a limit the catalogue does not state."""
    torques = []
    for value, name in ((point.peak_torque, "peak torque"), (point.continuous_torque, "continuous torque")):
        torques.append(f"{name}: unknown" if value is None else f"{name} {value:.3g} N·m")
    speed = (
        "max speed: unknown"
        if point.max_speed is None
        else f"max speed {point.max_speed:.3g} rad/s ({point.max_speed * RAD_PER_S_TO_RPM:.0f} rpm)"
    )
    rms = [] if point.rms_torque is None else [f"RMS torque {point.rms_torque:.3g} N·m"]
    return ", ".join(torques) + "\n" + ", ".join([speed, *rms])


def _margin_text(point: JointOperatingPoints) -> str:
    """``peak +35 %, RMS 14.3×, speed −4 %``: each margin as :func:`margin_text` says it.

    "none" where a limit or requirement is absent.
    """
    parts = []
    for name, value in margins(point).items():
        if value is None:
            parts.append(f"{name} none")
        elif math.isinf(value):
            parts.append(f"{name} unloaded")
        else:
            parts.append(f"{name} {margin_text(value)}")
    return "margins: " + ", ".join(parts)
