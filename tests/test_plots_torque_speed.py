"""Torque–speed figure: files written, envelope classification against hand cases, margins, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from collision_reflex.errors import InvalidParameter
from collision_reflex.plots.torque_speed import (
    JointOperatingPoints,
    margins,
    outside_envelope,
    plot_torque_speed,
)

PEAK = 2.0  # N*m
MAX_SPEED = 300.0  # rad/s


def _shoulder() -> JointOperatingPoints:
    # A cycle inside the envelope except two points: one 10 % over the peak torque, one 10 % over max speed.
    t = np.linspace(0.0, 1.0, 50)
    speed = 250.0 * np.sin(2 * np.pi * t)
    torque = 1.5 * np.cos(2 * np.pi * t)
    speed = np.append(speed, [-100.0, 1.1 * MAX_SPEED])
    torque = np.append(torque, [-1.1 * PEAK, 0.5])
    return JointOperatingPoints(
        joint="shoulder",
        speed=speed,
        torque=torque,
        approach_speed=np.array([40.0, -60.0, 320.0]),
        peak_torque=PEAK,
        continuous_torque=1.0,
        max_speed=MAX_SPEED,
        rms_torque=1.06,
    )


def _wrist_unknown_limits() -> JointOperatingPoints:
    return JointOperatingPoints(joint="wrist", speed=[10.0, -20.0], torque=[0.1, -0.3], continuous_torque=0.2)


@pytest.mark.parametrize("suffix", [".png", ".svg"])
def test_figure_is_written(tmp_path, suffix):
    joints = [
        _shoulder(),
        _wrist_unknown_limits(),
        JointOperatingPoints("elbow", [], [], approach_speed=[5.0]),
    ]
    target = plot_torque_speed(tmp_path / f"torque_speed{suffix}", joints)
    assert target.exists() and target.stat().st_size > 1000
    assert [p.name for p in tmp_path.iterdir()] == [target.name]  # the atomic save leaves no temporary file


def test_svg_says_unknown_and_motor_side(tmp_path):
    text = plot_torque_speed(tmp_path / "f.svg", [_wrist_unknown_limits()]).read_text(encoding="utf-8")
    # Matplotlib's SVG keeps each text as a comment beside its glyph paths.
    for label in (
        "peak torque: unknown",
        "max speed: unknown",
        "continuous torque 0.2 N·m",
        "joint torque / N",
    ):
        assert label in text
    assert "margins: peak none, RMS none, speed none" in text
    shoulder = plot_torque_speed(tmp_path / "g.svg", [_shoulder()]).read_text(encoding="utf-8")
    # Peak: 2 / 2.2 - 1; RMS: 1 / 1.06 - 1; speed: 300 / 330 - 1; each to 3 significant digits.
    assert "margins: peak −9.09 %, RMS −5.66 %, speed −9.09 %" in shoulder
    assert "max speed 300 rad/s (2865 rpm)" in shoulder


def test_classification_at_one_percent_either_side_of_each_limit():
    speed = np.array([0.0, 0.0, 0.99, 1.01, -1.01, 0.5]) * MAX_SPEED
    torque = np.array([0.99, 1.01, 0.0, 0.0, 0.0, -1.01]) * PEAK
    expected = [False, True, False, True, True, True]
    assert outside_envelope(speed, torque, PEAK, MAX_SPEED).tolist() == expected
    # A point exactly on a limit is inside.
    assert not outside_envelope([MAX_SPEED], [PEAK], PEAK, MAX_SPEED).any()
    # An unknown limit classifies nothing as outside it.
    assert outside_envelope(speed, torque, None, MAX_SPEED).tolist() == [
        False,
        False,
        False,
        True,
        True,
        False,
    ]
    assert outside_envelope(speed, torque, PEAK, None).tolist() == [False, True, False, False, False, True]


def test_classification_of_the_hand_made_cycle():
    point = _shoulder()
    outside = np.flatnonzero(outside_envelope(point.speed, point.torque, point.peak_torque, point.max_speed))
    assert outside.tolist() == [50, 51]


def test_margins_against_hand_values():
    point = _shoulder()
    found = margins(point)
    assert found["peak"] == pytest.approx(1 / 1.1 - 1, rel=1e-12)
    assert found["RMS"] == pytest.approx(1.0 / 1.06 - 1, rel=1e-12)
    # The cycle's 1.1 x 300 rad/s is faster than the approach's 320 rad/s.
    assert found["speed"] == pytest.approx(1 / 1.1 - 1, rel=1e-12)
    wrist = margins(_wrist_unknown_limits())
    assert wrist == {"peak": None, "RMS": None, "speed": None}
    unloaded = margins(JointOperatingPoints("j", [0.0], [0.0], peak_torque=1.0))
    assert unloaded["peak"] == math.inf


def test_approach_speed_sets_the_speed_margin_when_fastest():
    point = JointOperatingPoints("j", [100.0], [1.0], approach_speed=[-400.0], max_speed=MAX_SPEED)
    assert margins(point)["speed"] == pytest.approx(MAX_SPEED / 400.0 - 1, rel=1e-12)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"speed": [1.0, 2.0], "torque": [1.0]}, "torque"),
        ({"speed": [1.0, math.nan], "torque": [1.0, 2.0]}, "speed"),
        ({"speed": [1.0], "torque": [math.inf]}, "torque"),
        ({"approach_speed": [math.nan]}, "approach_speed"),
        ({"speed": [[1.0]], "torque": [[1.0]]}, "speed"),
        ({"peak_torque": -1.0}, "peak_torque"),
        ({"continuous_torque": 0.0}, "continuous_torque"),
        ({"max_speed": math.nan}, "max_speed"),
        ({"rms_torque": -0.1}, "rms_torque"),
        ({"peak_torque": "big"}, "peak_torque"),
        ({"max_speed": [1.0, 2.0]}, "max_speed"),
    ],
)
def test_bad_joint_data_names_joint_and_field(kwargs, field):
    arguments = {"speed": [1.0], "torque": [1.0], **kwargs}
    with pytest.raises(InvalidParameter, match=f"elbow: {field}"):
        JointOperatingPoints("elbow", **arguments)


def test_no_joints_or_bad_path_raise(tmp_path):
    with pytest.raises(InvalidParameter, match="joints"):
        plot_torque_speed(tmp_path / "f.png", [])
    with pytest.raises(InvalidParameter, match="figure file"):
        plot_torque_speed(tmp_path / "f.txt", [_shoulder()])
    with pytest.raises(InvalidParameter, match="joint"):
        JointOperatingPoints("", [1.0], [1.0])
    assert list(tmp_path.iterdir()) == []


def test_one_drawing_for_several_files_gives_the_pixels_of_each_drawn_alone(tmp_path):
    """A figure saved to its SVG and PNG at once is laid out once; its PNG is the one matplotlib crops alone."""
    from PIL import Image

    joints = [_shoulder(), _wrist_unknown_limits()]
    alone = plot_torque_speed(tmp_path / "alone.png", joints)
    first = plot_torque_speed((tmp_path / "both.svg", tmp_path / "both.png"), joints)
    assert first == tmp_path / "both.svg" and (tmp_path / "both.svg").read_text().startswith("<?xml")
    with Image.open(alone) as a, Image.open(tmp_path / "both.png") as b:
        assert a.size == b.size and a.tobytes() == b.tobytes()
    with pytest.raises(InvalidParameter, match="figure file"):
        plot_torque_speed((tmp_path / "ok.png", tmp_path / "bad.txt"), joints)
    with pytest.raises(InvalidParameter, match="at least one file"):
        plot_torque_speed((), joints)


def test_each_file_is_drawn_once_and_saved_whole(tmp_path, monkeypatch):
    """Saving the figure to its SVG and PNG draws it once per file: no layout pass, no tight bounding box.

    A figure left with a layout engine (``fig.tight_layout()`` leaves a placeholder) is drawn once more before
    each file by ``savefig``; a file cropped to the tight bounding box is measured by one more pass.
    """
    from matplotlib.figure import Figure
    from PIL import Image

    import collision_reflex.plots.torque_speed as module

    joints = [_shoulder(), _wrist_unknown_limits(), JointOperatingPoints("elbow", [1.0], [0.1])]
    drawn: list[Figure] = []
    draw = Figure.draw
    monkeypatch.setattr(Figure, "draw", lambda self, renderer: (drawn.append(self), draw(self, renderer))[1])
    sizes = []
    save = module.save_figure

    def keep_size(fig, path, **kwargs):
        assert fig.get_layout_engine() is None
        sizes.append(tuple(fig.get_size_inches()))
        return save(fig, path, **kwargs)

    monkeypatch.setattr(module, "save_figure", keep_size)
    plot_torque_speed((tmp_path / "f.svg", tmp_path / "f.png"), joints)
    assert len(drawn) == 2
    with Image.open(tmp_path / "f.png") as image:
        # The whole figure at 150 dpi (to the pixel matplotlib rounds it to).
        assert all(
            abs(pixels - 150 * inches) < 1 for pixels, inches in zip(image.size, sizes[0], strict=True)
        )


def _tiny_and_fast() -> JointOperatingPoints:
    # Six-character tick labels on both axes: y from 0.0000 N*m, rpm up to 10000.
    return JointOperatingPoints(
        joint="wrist_3_joint",
        speed=[900.0, -50.0],
        torque=[0.0003, 0.0001],
        approach_speed=[20.0],
        peak_torque=0.0004,
        continuous_torque=0.0002,
        max_speed=1000.0,
        rms_torque=0.0001,
    )


@pytest.mark.parametrize("suffix", [".png", ".svg"])
@pytest.mark.parametrize("count", [1, 2, 6, 7])
def test_no_text_overlaps_another_or_a_subplot_or_leaves_the_saved_figure(
    tmp_path, monkeypatch, count, suffix
):
    """Every text drawn (titles, labels, tick labels, legend) lies inside the saved figure and overlaps no
    other text, no subplot and not the legend; the legend overlaps no subplot."""
    from matplotlib.legend import Legend
    from matplotlib.text import Text

    import collision_reflex.plots.torque_speed as module

    drawn: dict[type, list] = {Text: [], Legend: []}

    def recording(kind):
        draw = kind.draw

        def record(self, renderer):
            draw(self, renderer)
            if self.get_visible() and (kind is Legend or self.get_text()):
                box = self.get_window_extent(renderer).transformed(self.figure.dpi_scale_trans.inverted())
                drawn[kind].append((self, box))

        return record

    for kind in drawn:
        monkeypatch.setattr(kind, "draw", recording(kind))
    figures = []
    save = module.save_figure
    monkeypatch.setattr(
        module, "save_figure", lambda fig, path, **kw: (figures.append(fig), save(fig, path, **kw))[1]
    )
    kinds = [
        _shoulder(),
        _wrist_unknown_limits(),
        _tiny_and_fast(),
        JointOperatingPoints("elbow", [1.0], [0.1]),
    ]
    plot_torque_speed(tmp_path / f"f{suffix}", (kinds * 2)[:count])
    (fig,) = figures
    width, height = fig.get_size_inches()
    ((legend, legend_box),) = drawn[Legend]
    in_legend = set(legend.get_texts())
    inches = fig.dpi_scale_trans.inverted()
    subplots = [
        ax.get_position().transformed(fig.transFigure).transformed(inches)
        for ax in fig.axes
        if ax.get_visible()
    ]
    assert len(subplots) == count
    texts = [(text, box) for text, box in drawn[Text] if text not in in_legend]
    assert len(texts) > 15 * count  # tick labels included
    for text, box in drawn[Text]:
        assert 0 <= box.x0 and box.x1 <= width and 0 <= box.y0 and box.y1 <= height, text.get_text()
    for index, (text, box) in enumerate(texts):
        for other, other_box in texts[index + 1 :]:
            assert not box.overlaps(other_box), (text.get_text(), other.get_text())
        for subplot in [*subplots, legend_box]:
            assert not box.overlaps(subplot), text.get_text()
    for subplot in subplots:
        assert not legend_box.overlaps(subplot)


@pytest.mark.parametrize("count", [2, 3])
def test_one_shared_legend_of_the_kinds_drawn_outside_every_subplot(tmp_path, monkeypatch, count):
    """One figure legend lists each kind drawn once and covers no subplot (an empty cell, or below the grid)."""
    import matplotlib.pyplot as plt

    import collision_reflex.plots.torque_speed as module

    captured = []
    monkeypatch.setattr(module, "save_figure", lambda fig, path, **kwargs: captured.append(fig))
    joints = [_shoulder(), _wrist_unknown_limits(), JointOperatingPoints("elbow", [1.0], [0.1])][:count]
    plot_torque_speed(tmp_path / "f.png", joints)
    fig = captured[0]
    try:
        renderer = fig.canvas.get_renderer()
        assert [ax.get_legend() for ax in fig.axes] == [None] * len(fig.axes)
        (legend,) = fig.legends
        # The shoulder draws every kind (its RMS torque 1.06 N*m is over its continuous 1 N*m); the others none.
        assert [text.get_text() for text in legend.get_texts()] == [
            "peak torque, max speed",
            "continuous torque",
            "duty cycle",
            "outside the envelope",
            "approach",
            "approach, too fast",
            "RMS torque above continuous",
        ]
        box = legend.get_window_extent(renderer)
        for ax in fig.axes:
            if ax.get_visible():
                assert not box.overlaps(ax.get_window_extent(renderer))
    finally:
        plt.close(fig)


def test_points_on_one_spot_are_drawn_once_and_none_outside_is_lost(tmp_path, monkeypatch):
    """A cycle run three times draws each spot of it once; a point outside beside one inside keeps its red."""
    import matplotlib.pyplot as plt

    import collision_reflex.plots.torque_speed as module

    captured, kinds = [], {}
    monkeypatch.setattr(module, "save_figure", lambda fig, path, **kwargs: captured.append(fig))
    shared = module._shared_legend
    monkeypatch.setattr(
        module, "_shared_legend", lambda fig, legend, *a: (kinds.update(legend), shared(fig, legend, *a))[1]
    )
    once = _shoulder()
    # A point a millionth over the peak torque beside one on it: the same spot, but one of each kind.
    speed = np.concatenate([np.tile(once.speed, 3), [10.0, 10.0]])
    torque = np.concatenate([np.tile(once.torque, 3), [PEAK, PEAK * (1 + 1e-6)]])
    approach = np.tile(once.approach_speed, 5)
    fields = {
        name: getattr(once, name) for name in ("peak_torque", "continuous_torque", "max_speed", "rms_torque")
    }
    plot_torque_speed(
        tmp_path / "f.png", [JointOperatingPoints("shoulder", speed, torque, approach, **fields)]
    )
    fig = captured[0]
    try:
        drawn = {
            label: np.column_stack(kinds[label].get_data())
            for label in kinds
            if label.startswith(("duty", "out", "appr"))
        }
        spot = module.SPOT * np.array([fig.axes[0].get_xlim()[1], fig.axes[0].get_ylim()[1]])
    finally:
        plt.close(fig)
    inside = ~outside_envelope(once.speed, once.torque, PEAK, MAX_SPEED)
    cycle = np.column_stack([np.abs(once.speed), np.abs(once.torque)])[inside]
    # Every point drawn is a point of the cycle, every point of the cycle is drawn within a spot, and the three
    # runs of the cycle (folded onto |speed|, |torque|, its halves coincide) are drawn as fewer points than one.
    duty = drawn["duty cycle"]
    assert duty[-1].tolist() == [10.0, PEAK]
    assert all(np.any(np.all(point == cycle, axis=1)) for point in duty[:-1])
    assert all(np.min(np.max(np.abs(duty - point) / spot, axis=1)) <= 1 for point in cycle)
    assert len(duty) < len(cycle)
    assert drawn["outside the envelope"].tolist() == [
        [100.0, 1.1 * PEAK],
        [1.1 * MAX_SPEED, 0.5],
        [10.0, PEAK * (1 + 1e-6)],
    ]
    assert drawn["approach"].tolist() == [[40.0, 0.0], [60.0, 0.0]]
    assert drawn["approach, too fast"].tolist() == [[320.0, 0.0]]


def test_rpm_scale_labels_round_rpm_at_their_speed(tmp_path, monkeypatch):
    """The top scale's labels are round rpm, evenly stepped over the subplot, each at its speed in rad/s."""
    import matplotlib.pyplot as plt

    import collision_reflex.plots.torque_speed as module

    captured = []
    monkeypatch.setattr(module, "save_figure", lambda fig, path, **kwargs: captured.append(fig))
    plot_torque_speed(tmp_path / "f.png", [_shoulder()])
    (ax,) = captured[0].axes
    try:
        texts = {text.get_text(): text for text in ax.texts}
        assert "motor speed [rpm]" in texts
        ticks = [
            (float(label), text.get_position()[0]) for label, text in texts.items() if label[0].isdigit()
        ]
        top = ax.get_xlim()[1] * module.RAD_PER_S_TO_RPM
    finally:
        plt.close(captured[0])
    rpm, at = np.array(ticks).T
    # Up to 1.15 x 330 rad/s: 0 to 3500 rpm in steps of 500.
    assert rpm.tolist() == [500.0 * k for k in range(8)] and top < 4000
    np.testing.assert_allclose(at, rpm / module.RAD_PER_S_TO_RPM, rtol=1e-12)
