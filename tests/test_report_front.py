"""The report's Pareto front: a marker per design that the page's script finds, flat objectives drawn flat, hover
cards in designer units, and hovering a point in headless Chromium shows that design's card."""

from __future__ import annotations

import contextlib
import fcntl
import json
import os
import re
import select
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from collision_reflex.plots import design_front
from collision_reflex.plots.design_front import plot_design_front
from collision_reflex.report.front import front_cards
from collision_reflex.report.pdf import find_browser, headless_flags

ROOT = Path(__file__).resolve().parents[1]
TWO_LINK = ROOT / "studies" / "two_link_paper.yaml"
TIMEOUT = 60.0  # [s] for any one reply or event from the browser


def _point_ids(svg: str) -> list[int]:
    return [int(i) for i in re.findall(r'<g id="front-point-(\d+)">', svg)]


def _drawn(monkeypatch: pytest.MonkeyPatch) -> list[Any]:
    """The figures ``plot_design_front`` draws, kept for inspection (it closes them once saved)."""
    figures: list[Any] = []
    save = design_front.save_figure

    def keep(figure: Any, path: Any, **kwargs: Any) -> Path:
        figures.append(figure)
        return save(figure, path, **kwargs)

    monkeypatch.setattr(design_front, "save_figure", keep)
    return figures


# ---- (a) one SVG group per design --------------------------------------------------------------------------------


@pytest.mark.parametrize("objectives", [2, 3])
def test_each_design_is_its_own_svg_group(tmp_path, objectives):
    values = np.column_stack([np.linspace(1.0, 2.0, 7), np.linspace(3.0, 1.0, 7), np.linspace(5.0, 9.0, 7)])
    names, units = ["worst_case_impulse", "actuator_mass", "mean_impulse"], ["N*s", "kg", "N*s"]
    path = plot_design_front(
        tmp_path / "front.svg",
        names[:objectives],
        units[:objectives],
        values[:, :objectives],
        chosen=[1.0, 3.0],
        recommended=[1.5, 2.0],
    )
    svg = path.read_text(encoding="utf-8")
    assert _point_ids(svg) == list(range(7))


# ---- (b) flat objectives ------------------------------------------------------------------------------------------


def test_a_flat_objective_is_centred_at_five_percent_and_says_how_flat(tmp_path, monkeypatch):
    figures = _drawn(monkeypatch)
    flat = 2.6250 * (1 + np.linspace(0.0, 2e-4, 6))  # spans 0.020 % of its best (the minimum)
    steep = np.linspace(0.131, 0.124, 6)  # spans 5.6 %
    plot_design_front(
        tmp_path / "front.svg", ["worst_case_impulse", "actuator_mass"], ["N*s", "kg"], np.c_[flat, steep]
    )
    (ax, *_) = figures[0].axes
    low, high = ax.get_xlim()
    centre = 0.5 * (flat.min() + flat.max())
    slack = 1e-12 * centre  # the limits are 5 % to rounding
    assert low <= 0.95 * centre + slack and high >= 1.05 * centre - slack
    assert abs(0.5 * (low + high) - centre) <= 1e-9 * centre
    assert "flat: all designs within 0.020 %" in ax.get_xlabel()
    assert "flat" not in ax.get_ylabel()
    # The steep axis is still fitted to its points, not widened.
    assert ax.get_ylim()[1] - ax.get_ylim()[0] < 2 * (steep.max() - steep.min())
    assert ax.get_title() == "Pareto front: 6 designs"


def test_a_front_flat_in_both_objectives_is_drawn_flat_on_both_axes(tmp_path, monkeypatch):
    figures = _drawn(monkeypatch)
    values = np.c_[15.04 * (1 + np.array([0.0, 1e-5, 3e-5])), 10.14 * (1 + np.array([2e-3, 1e-3, 0.0]))]
    plot_design_front(
        tmp_path / "front.svg",
        ["worst_case_impulse", "actuator_mass"],
        ["N*s", "kg"],
        values,
        flat_span=1.0,
    )
    (ax, *_) = figures[0].axes
    for limits, label, column, span in (
        (ax.get_xlim(), ax.get_xlabel(), values[:, 0], "0.0030 %"),
        (ax.get_ylim(), ax.get_ylabel(), values[:, 1], "0.20 %"),
    ):
        centre = 0.5 * (column.min() + column.max())
        slack = 1e-12 * centre
        assert limits[0] <= 0.95 * centre + slack and limits[1] >= 1.05 * centre - slack
        assert f"flat: all designs within {span}" in label


def test_flat_span_sets_what_counts_as_flat(tmp_path, monkeypatch):
    figures = _drawn(monkeypatch)
    values = np.c_[np.array([1.0, 1.005, 1.01]), np.array([3.0, 2.0, 1.0])]  # the first spans 1.0 %
    plot_design_front(tmp_path / "a.svg", ["a", "b"], ["N*s", "kg"], values, flat_span=1.0)
    plot_design_front(tmp_path / "b.svg", ["a", "b"], ["N*s", "kg"], values, flat_span=2.0)
    assert "flat" not in figures[0].axes[0].get_xlabel()
    assert "flat: all designs within 1.0 %" in figures[1].axes[0].get_xlabel()


# ---- (c) the cards ------------------------------------------------------------------------------------------------


def _joint(name: str, diameter: float, stack: float, ratio: float, stiffness: float, gearbox: str | None):
    return {
        "joint": name,
        "stator_diameter": diameter,
        "stack_length": stack,
        "gear_ratio": ratio,
        "software_stiffness": stiffness,
        "actuator_mass": 1.2,
        "gearbox": gearbox,
    }


def _record(impulse: float, mass: float, threshold: float, sensing: str = "force") -> dict[str, Any]:
    return {
        "label": "anchor",
        "objectives": {"worst_case_impulse": impulse, "actuator_mass": mass, "mean_impulse": 0.3460225},
        "threshold": threshold,
        "sensing": sensing,
        "approach_velocity": 0.132101,
        "joints": [
            _joint("shoulder_pan_joint", 0.0763076, 0.0125, 123.2899, 4997.818, "strain wave"),
            _joint("wrist_1_joint", 0.0300002, 0.0181234, 1.0, 512.34, None),
        ],
    }


RESULTS: dict[str, Any] = {
    "kind": "arm",
    "pareto": {
        "objectives": ["worst_case_impulse", "actuator_mass"],
        "points": [_record(9.859003, 8.884977, 2.0000446), _record(26.04580, 3.21, 0.0015, "position")],
    },
    "recommended": {"pareto_index": 1},
    "catalogue": {
        "pareto": [
            {"parts": ["M1 + G1 at N = 100", "M2"], "feasible": True, "missing": [], "shortfalls": []},
            {
                "parts": ["M1 + G1 at N = 100", "M2"],
                "feasible": False,
                "missing": [],
                "shortfalls": [
                    "shoulder_pan_joint: gearbox peak rating 333 N*m below the required 333.8 N*m"
                ],
            },
        ]
    },
}

_NUMBER = r"(-?\d+(?:\.\d+)?(?:e[+-]?\d+)?)"


def _value(lines: list[str], pattern: str) -> float:
    """The number in the one line that matches ``pattern`` (a regex with one group for the number)."""
    found = [m for line in lines if (m := re.fullmatch(pattern, line))]
    assert len(found) == 1, (pattern, lines)
    return float(found[0].group(1))


def test_cards_give_each_design_in_designer_units():
    cards = front_cards(RESULTS)
    assert [card["id"] for card in cards] == ["front-point-0", "front-point-1"]
    assert [card["title"] for card in cards] == ["Pareto design 0", "Pareto design 1 — recommended"]
    for card, record in zip(cards, RESULTS["pareto"]["points"], strict=True):
        lines = card["lines"]
        objectives = record["objectives"]
        # 4 significant digits: within half a unit of the 4th digit, so 10 % off (or a wrong unit) fails.
        for name, unit in (("worst case impulse", "N·s"), ("actuator mass", "kg"), ("mean impulse", "N·s")):
            shown = _value(lines, rf"{name} {_NUMBER} {unit}")
            assert shown == pytest.approx(objectives[name.replace(" ", "_")], rel=5e-4)
        # The front's objectives first.
        assert [line.split(" ", 2)[:2] for line in lines[:2]] == [["worst", "case"], ["actuator", "mass"]]
        assert _value(lines, rf"approach velocity {_NUMBER} m/s") == pytest.approx(0.132101, rel=5e-4)
        for joint in record["joints"]:
            pattern = (
                rf"{joint['joint']}: {_NUMBER} mm × (\S+) mm motor, N = (\S+), k_s (\S+) N·m/rad(?:; (.+))?"
            )
            (match,) = [m for line in lines if (m := re.fullmatch(pattern, line))]
            assert float(match.group(1)) == pytest.approx(joint["stator_diameter"] * 1e3, rel=5e-3)
            assert float(match.group(2)) == pytest.approx(joint["stack_length"] * 1e3, rel=5e-3)
            assert float(match.group(3)) == pytest.approx(joint["gear_ratio"], rel=5e-4)
            assert float(match.group(4)) == pytest.approx(joint["software_stiffness"], rel=5e-4)
            assert match.group(5) == joint["gearbox"]
    first, second = (card["lines"] for card in cards)
    assert "shoulder_pan_joint: 76.3 mm × 12.5 mm motor, N = 123.3, k_s 4998 N·m/rad; strain wave" in first
    assert "wrist_1_joint: 30 mm × 18.1 mm motor, N = 1, k_s 512.3 N·m/rad" in first
    assert _value(first, rf"threshold {_NUMBER} N") == pytest.approx(2.0000446, rel=5e-4)
    # A position-error threshold is a length: in mm.
    assert _value(second, rf"position-error threshold {_NUMBER} mm") == pytest.approx(1.5, rel=5e-4)
    assert first[-1] == "catalogue parts: M1 + G1 at N = 100, M2 (meets the requirements)"
    assert second[-1] == (
        "catalogue parts: M1 + G1 at N = 100, M2 "
        "(misses: shoulder_pan_joint: gearbox peak rating 333 N·m below the required 333.8 N·m)"
    )


def test_cards_without_catalogue_or_recommendation_and_with_a_missing_part():
    results = {**RESULTS, "recommended": {"source": "chosen"}}
    del results["catalogue"]
    cards = front_cards(results)
    assert [card["title"] for card in cards] == ["Pareto design 0", "Pareto design 1"]
    assert not any(line.startswith("catalogue") for card in cards for line in card["lines"])
    missing = {
        "parts": ["M1", None],
        "feasible": False,
        "missing": [{"joint": "wrist_1_joint", "nearest": "M9", "misses": ["too heavy", "too slow"]}],
        "shortfalls": [],
    }
    results["catalogue"] = {"pareto": [missing]}  # a snap of the first design only
    first, second = front_cards(results)
    assert first["lines"][-1] == (
        "catalogue parts: M1, none (misses: wrist_1_joint: no part within bounds, nearest M9 misses too heavy, "
        "too slow)"
    )
    assert not second["lines"][-1].startswith("catalogue")


def test_a_gearbox_every_joint_shares_is_said_once_and_repeated_parts_are_counted():
    record = _record(9.859003, 8.884977, 2.0)
    for joint in record["joints"]:
        joint["gearbox"] = "harmonic scaled from CSF-17-100-2UH (at most CSF-32-100-2UH's 333 N*m)"
    snap = {"parts": ["A + G at N = 50"] * 2, "feasible": True, "missing": [], "shortfalls": []}
    results = {
        "pareto": {"objectives": ["worst_case_impulse"], "points": [record]},
        "catalogue": {"pareto": [snap]},
    }
    (card,) = front_cards(results)
    assert [line for line in card["lines"] if "harmonic" in line] == [
        "gearbox of every joint: harmonic scaled from CSF-17-100-2UH (at most CSF-32-100-2UH's 333 N·m)"
    ]
    assert card["lines"][-1] == "catalogue parts: 2 × A + G at N = 50 (meets the requirements)"


# ---- (d) hovering a point in headless Chromium --------------------------------------------------------------------


class PipeBrowser:
    """A headless Chromium driven through the DevTools protocol over ``--remote-debugging-pipe``.

    Chromium reads commands from its file descriptor 3 and writes replies and events to 4, each message JSON
    ended by a NUL byte. Every wait is bounded by :data:`TIMEOUT`.
    """

    def __init__(self, browser: str, profile: Path) -> None:
        commands_read, self._commands = os.pipe()
        self._replies, replies_write = os.pipe()
        # Both pipes are open, so descriptors 3 and 4 are open here (os.pipe takes the lowest free ones):
        # pass_fds=(3, 4) keeps them in the child, where the pipe ends are moved onto them first. The ends are
        # copied above 10 so that neither move closes the other's end.
        high_read = fcntl.fcntl(commands_read, fcntl.F_DUPFD_CLOEXEC, 10)
        high_write = fcntl.fcntl(replies_write, fcntl.F_DUPFD_CLOEXEC, 10)

        def onto_3_and_4() -> None:
            os.dup2(high_read, 3)
            os.dup2(high_write, 4)

        try:
            self.process = subprocess.Popen(
                [browser, *headless_flags(str(profile)), "--remote-debugging-pipe", "about:blank"],
                stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
                pass_fds=(3, 4),
                preexec_fn=onto_3_and_4,
            )
        except BaseException:
            os.close(self._commands)
            os.close(self._replies)
            raise
        finally:
            for fd in (commands_read, replies_write, high_read, high_write):
                os.close(fd)
        self._buffer = b""
        self._next_id = 0
        self.events: list[dict[str, Any]] = []

    def close(self) -> None:
        """Ask the browser to quit (it takes its helper processes with it), kill it if it has not soon."""
        with contextlib.suppress(OSError):  # already gone
            os.write(self._commands, json.dumps({"id": 0, "method": "Browser.close"}).encode() + b"\0")
        os.close(self._commands)
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait(timeout=TIMEOUT)
        finally:
            os.close(self._replies)

    def _message(self, deadline: float) -> dict[str, Any]:
        while b"\0" not in self._buffer:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([self._replies], [], [], left)[0]:
                raise TimeoutError("no message from Chromium in time")
            chunk = os.read(self._replies, 1 << 16)
            if not chunk:
                raise ConnectionError("Chromium closed the DevTools pipe")
            self._buffer += chunk
        message, self._buffer = self._buffer.split(b"\0", 1)
        return json.loads(message)

    def send(self, method: str, session: str | None = None, **params: Any) -> dict[str, Any]:
        """Send a command and wait for its reply; events that arrive meanwhile are kept in :attr:`events`."""
        self._next_id += 1
        command: dict[str, Any] = {"id": self._next_id, "method": method, "params": params}
        if session is not None:
            command["sessionId"] = session
        os.write(self._commands, json.dumps(command).encode() + b"\0")
        deadline = time.monotonic() + TIMEOUT
        while True:
            message = self._message(deadline)
            if message.get("id") == self._next_id:
                if "error" in message:
                    raise RuntimeError(f"{method}: {message['error']}")
                return message["result"]
            self.events.append(message)

    def wait_for(self, method: str, after: int = 0) -> dict[str, Any]:
        """The first event ``method`` from :attr:`events` ``[after:]`` on (kept, or arriving before :data:`TIMEOUT`)."""
        deadline = time.monotonic() + TIMEOUT
        while True:
            for event in self.events[after:]:
                if event.get("method") == method:
                    return event
            self.events.append(self._message(deadline))

    def evaluate(self, session: str, expression: str) -> Any:
        reply = self.send("Runtime.evaluate", session, expression=expression, returnByValue=True)
        assert "exceptionDetails" not in reply, reply["exceptionDetails"]
        return reply["result"].get("value")


@contextlib.contextmanager
def open_page(browser: str, profile: Path, url: str) -> Iterator[tuple[PipeBrowser, str]]:
    """A browser with ``url`` loaded in a page of a fixed size, and that page's session id."""
    chromium = PipeBrowser(browser, profile)
    try:
        target = chromium.send("Target.createTarget", url="about:blank")["targetId"]
        session = chromium.send("Target.attachToTarget", targetId=target, flatten=True)["sessionId"]
        for domain in ("Page", "Runtime", "Log"):
            chromium.send(f"{domain}.enable", session)
        chromium.send(
            "Emulation.setDeviceMetricsOverride",
            session,
            width=1280,
            height=900,
            deviceScaleFactor=1,
            mobile=False,
        )
        before = len(chromium.events)
        chromium.send("Page.navigate", session, url=url)
        chromium.wait_for("Page.loadEventFired", after=before)
        # The blank page's own load may have been the event: wait until this page has loaded.
        loaded = f"document.readyState === 'complete' && location.href === {json.dumps(url)}"
        deadline = time.monotonic() + TIMEOUT
        while not chromium.evaluate(session, loaded):
            assert time.monotonic() < deadline, f"{url} did not load in time"
            time.sleep(0.05)
        yield chromium, session
    finally:
        chromium.close()


def _errors(events: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The console errors, uncaught exceptions and failed loads among DevTools events."""
    return [
        event
        for event in events
        if event.get("method") == "Runtime.exceptionThrown"
        or (event.get("method") == "Runtime.consoleAPICalled" and event["params"]["type"] == "error")
        or (event.get("method") == "Log.entryAdded" and event["params"]["entry"]["level"] == "error")
    ]


# The last point whose centre the pointer would reach (not covered by another point, a label or the legend),
# scrolled into view: [index, x, y] in viewport pixels, or null.
_HOVERABLE = """(() => {
  const points = [...document.querySelectorAll('#front [id^="front-point-"]')].reverse();
  for (const point of points) {
    point.scrollIntoView({block: "center"});
    const box = point.getBoundingClientRect();
    const x = box.x + box.width / 2, y = box.y + box.height / 2;
    const hit = document.elementFromPoint(x, y);
    if (hit && hit.closest('[id^="front-point-"]') === point) {
      return [Number(point.id.slice("front-point-".length)), x, y];
    }
  }
  return null;
})()"""


@pytest.fixture(scope="module")
def report(smoke_runs) -> Path:
    """The two-link study run (smoke size): its report.html and designs.json."""
    return smoke_runs[TWO_LINK.stem]


def test_hovering_a_point_shows_its_design(report, tmp_path):
    browser = find_browser()
    if browser is None:
        pytest.skip("no Chromium installed (apt-get install chromium): the hover test needs a browser")
    results = json.loads((report / "designs.json").read_text(encoding="utf-8"))
    points = results["pareto"]["points"]
    html = (report / "report.html").read_text(encoding="utf-8")
    assert len(points) >= 2, "the smoke front needs two designs for a figure"
    assert sorted(_point_ids(html)) == list(range(len(points)))
    with open_page(browser, tmp_path / "profile", (report / "report.html").as_uri()) as (chromium, session):
        before = chromium.evaluate(session, "document.getElementById('front-card').textContent")
        assert "Hover a point (or focus it with Tab) to see its design." in before
        assert chromium.evaluate(session, "document.getElementById('front-point-0').tabIndex") == 0
        found = chromium.evaluate(session, _HOVERABLE)
        assert found is not None, "no front point is reachable by the pointer"
        index, x, y = found
        chromium.send("Input.dispatchMouseEvent", session, type="mouseMoved", x=x, y=y)
        card = chromium.evaluate(session, "document.getElementById('front-card').innerText")
        highlighted = chromium.evaluate(
            session, f"document.getElementById('front-point-{index}').style.transform"
        )
        errors = _errors(chromium.events)
    assert not errors, errors
    lines = card.splitlines()
    assert lines[0] == f"Pareto design {index}" + (
        " — recommended" if results.get("recommended", {}).get("pareto_index") == index else ""
    )
    from collision_reflex.optimize import OBJECTIVES

    for name, value in points[index]["objectives"].items():
        unit = OBJECTIVES[name][1].replace("*", "·")
        shown = _value(lines, rf"{name.replace('_', ' ')} {_NUMBER} {re.escape(unit)}")
        assert shown == pytest.approx(value, rel=5e-4), name
    assert highlighted  # the hovered point is marked
