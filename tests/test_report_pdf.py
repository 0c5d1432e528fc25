"""The printed report (``crx report DIR --pdf``) holds every number of the HTML tables; each shipped study's
report stays within its budget (words, pages), says each paragraph once, and prints no solver noise, one unit
per quantity and no local paths.

Every number of every table visible in print must appear in ``pdftotext``'s text of the PDF at least as often:
a table cut at the page edge, a column lost to a scrollbar, or a ``<details>`` section printed folded fails it.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from collections import Counter
from html.parser import HTMLParser
from pathlib import Path

import pytest

from collision_reflex.report.html import SOLVER_TOLERANCE, _settled_rows, settled
from collision_reflex.report.pdf import find_browser, html_to_pdf

ROOT = Path(__file__).resolve().parents[1]
STUDIES = {path.stem: path for path in sorted((ROOT / "studies").glob("*.yaml"))}
ARM = "two_link_paper"

WORDS = 2500
PAGES = 8
"""The budget of every shipped study's report: what a colleague reads through."""
NUMBER = re.compile(r"(?<![\w.−-])[−-]?\d+(?:\.\d+)?(?:e[+−-]?\d+)?(?![\w.])")


class _PrintedTables(HTMLParser):
    """Cell texts of the tables that print (not inside a ``screen-only`` element), with their headers.

    ``labelled`` pairs each data cell with its column's header and its row's first cell (the quantity of a row in a
    table printed transposed).
    """

    def __init__(self) -> None:
        super().__init__()
        self.cells: list[str] = []
        self.headers: list[str] = []
        self.labelled: list[tuple[str, str, str]] = []
        self.stack: list[bool] = []  # per open element: hidden in print?
        self.cell: list[str] | None = None
        self.header = False
        self.columns: list[str] = []  # the header row of the table being read
        self.row: list[str] = []
        self.row_of_headers = True

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        classes = (dict(attrs).get("class") or "").split()
        hidden = bool(self.stack and self.stack[-1]) or "screen-only" in classes
        if tag not in ("br", "meta", "col", "img"):
            self.stack.append(hidden)
        if tag == "table":
            self.columns = []
        if tag == "tr":
            self.row, self.row_of_headers = [], True
        if tag in ("td", "th") and not hidden:
            self.cell, self.header = [], tag == "th"

    def handle_endtag(self, tag: str) -> None:
        if tag in ("td", "th") and self.cell is not None:
            text = " ".join("".join(self.cell).split())
            (self.headers if self.header else self.cells).append(text)
            self.row_of_headers &= self.header
            if not self.header:
                column = self.columns[len(self.row)] if len(self.row) < len(self.columns) else ""
                self.labelled.append((column, self.row[0] if self.row else "", text))
            self.row.append(text)
            self.cell = None
        if tag == "tr" and not self.columns and self.row and self.row_of_headers:
            self.columns = self.row
        if self.stack and tag not in ("br", "meta", "col", "img"):
            self.stack.pop()

    def handle_data(self, data: str) -> None:
        if self.cell is not None:
            self.cell.append(data)


def printed_tables(html: str) -> _PrintedTables:
    parser = _PrintedTables()
    parser.feed(html)
    return parser


def _printed_report(folder: Path, smoke_run: Path) -> None:
    """The report of a copy of ``smoke_run`` (a study's shared smoke run) printed to PDF in ``folder / "out"``.

    Printed from smoke runs: ur5_human_contact's keeps its whole front of four; every study's full-size report
    is held to the same budget by ``benchmarks/report_budget.py`` (exit status 1 over it), ur5's longest front
    and two_link_planetary's eight pages among them (``benchmarks/results/report_budget.md``).
    """
    out = folder / "out"
    shutil.copytree(smoke_run, out)
    html_to_pdf(out / "report.html", out / "report.pdf")  # what crx report --pdf prints (test_study_run)


@pytest.fixture(scope="module")
def reports(shared_folder, smoke_runs) -> dict[str, Path]:
    """Every shipped study's printed report (:func:`_printed_report`), made when a test first asks for it."""
    if find_browser() is None or shutil.which("pdftotext") is None:
        pytest.skip("printing needs Chromium and pdftotext (apt-get install chromium poppler-utils)")

    class Printed(dict):
        def __missing__(self, name: str) -> Path:
            self[name] = (
                shared_folder(f"pdf-{name}", lambda folder: _printed_report(folder, smoke_runs[name])) / "out"
            )
            return self[name]

    return Printed()


# Each study's tests on one pytest-xdist worker, which prints its report once.
PER_STUDY = [pytest.param(name, marks=pytest.mark.xdist_group(f"pdf-{name}")) for name in STUDIES]


def _pdf_text(folder: Path) -> str:
    text = subprocess.run(
        ["pdftotext", "-layout", str(folder / "report.pdf"), "-"], capture_output=True, text=True, check=True
    ).stdout
    # pdftotext drops the thin space between a number and its unit ("1 N" comes out "1N"): put it back.
    return re.sub(r"(\d)(?=[A-DF-Za-df-zΩ°µ]|[eE](?![+−-]?\d))", r"\1 ", text)


class _Visible(HTMLParser):
    """The text a reader sees in the HTML (no style, script or figure), and its paragraphs."""

    def __init__(self) -> None:
        super().__init__()
        self.words: list[str] = []
        self.paragraphs: list[str] = []
        self.skip = 0
        self.paragraph: list[str] | None = None

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        if tag in ("style", "script", "svg"):
            self.skip += 1
        if tag in ("p", "li", "figcaption") and not self.skip:
            self.paragraph = []

    def handle_endtag(self, tag: str) -> None:
        if tag in ("style", "script", "svg"):
            self.skip -= 1
        if tag in ("p", "li", "figcaption") and self.paragraph is not None:
            self.paragraphs.append(" ".join("".join(self.paragraph).split()))
            self.paragraph = None

    def handle_data(self, data: str) -> None:
        if not self.skip:
            self.words += data.split()
            if self.paragraph is not None:
                self.paragraph.append(data)


def visible(html: str) -> _Visible:
    parser = _Visible()
    parser.feed(html)
    return parser


@pytest.mark.parametrize("name", PER_STUDY)
def test_each_report_is_within_its_budget_and_says_each_paragraph_once(reports, name):
    folder = reports[name]
    seen = visible((folder / "report.html").read_text())
    assert 200 < len(seen.words) <= WORDS, len(seen.words)  # every word of the page, folded tables too
    printed = _pdf_text(folder)
    assert len(printed.split()) <= WORDS
    pages = printed.count("\f")  # pdftotext ends every page with a form feed
    assert 1 <= pages <= PAGES, pages
    paragraphs = [p for p in seen.paragraphs if len(p.split()) >= 6]
    repeated = [p for p, count in Counter(paragraphs).items() if count > 1]
    assert paragraphs and not repeated, repeated


@pytest.mark.parametrize("name", PER_STUDY)
def test_margins_print_as_percentages_or_plain_multiples(reports, name):
    cells = printed_tables((reports[name] / "report.html").read_text()).labelled
    margins = [cell for column, _, cell in cells if "margin" in column and cell != "–"]
    assert all(re.fullmatch(r"0 %|[+−]\d+(\.\d+)? %|[\d,]+(\.\d+)?×", m) for m in margins), margins
    html = (reports[name] / "report.html").read_text()
    assert not re.search(r"\de[+-]\d+ %", html)  # never "8.37e+04 %"


@pytest.mark.parametrize("kind", PER_STUDY)
def test_every_table_number_is_in_the_pdf(reports: dict[str, Path], kind: str) -> None:
    folder = reports[kind]
    tables = printed_tables((folder / "report.html").read_text())
    wanted = Counter(n for cell in tables.cells for n in NUMBER.findall(cell))
    found = Counter(NUMBER.findall(_pdf_text(folder)))
    missing = {number: count - found[number] for number, count in wanted.items() if found[number] < count}
    assert sum(wanted.values()) > 30  # the tables are there to be checked
    assert not missing, f"numbers of the HTML tables missing from the PDF: {missing}"


def test_solver_noise_is_settled_to_zero() -> None:
    assert settled(-9.74e-9) == 0.0  # a margin of -9.74e-07 %, met to the solver's tolerance
    assert settled(3.562e-15, 1.3) == 0.0  # a required torque beside a 1.3 N*m peak torque
    assert settled(-2e-5) == -2e-5 and settled(2e-5 * 1.3, 1.3) == 2e-5 * 1.3  # beyond the tolerance: kept
    assert settled("OPN-060-013-A", 1.3) == "OPN-060-013-A"


def test_pareto_rows_settle_required_torques_and_margins() -> None:
    row = {
        "required_torque[j1] [N*m]": 3.562e-15,
        "peak_torque[j1] [N*m]": 1.3,
        "required_rms_torque[j1] [N*m]": 0.25,
        "torque_margin[j1] [-]": 1.703e-06,
        "speed_margin[j1] [-]": 0.0175,
        "reflected_inertia[j1] [kg*m^2]": 2.2e-7,  # small, but a value: untouched
    }
    assert _settled_rows([row]) == [{**row, "required_torque[j1] [N*m]": 0.0, "torque_margin[j1] [-]": 0.0}]


@pytest.mark.xdist_group(f"pdf-{ARM}")
def test_printed_margins_and_torques_carry_no_solver_noise(reports: dict[str, Path]) -> None:
    cells = printed_tables((reports[ARM] / "report.html").read_text()).labelled
    margins = [
        float(cell.rstrip(" %").replace("−", "-"))
        for column, _, cell in cells
        if "margin" in column and cell.endswith(" %")
    ]
    assert margins  # the joint tables have margins
    # 0, or at least the tolerance (in per cent): nothing like -9.74e-07 %.
    assert all(m == 0 or abs(m) >= 100 * SOLVER_TOLERANCE for m in margins), margins
    # No tiny number where a torque or a margin is printed (an inertia of 5e-8 kg*m^2 is a value, not noise).
    tiny = re.compile(r"-?\d(\.\d+)?e-(0[6-9]|[1-9]\d)")
    noise = [
        (column, row, cell)
        for column, row, cell in printed_tables((reports[ARM] / "report.html").read_text()).labelled
        if tiny.fullmatch(cell) and "inertia" not in column + row
    ]
    assert not noise


@pytest.mark.parametrize("kind", PER_STUDY)
def test_one_unit_per_quantity_across_tables(reports: dict[str, Path], kind: str) -> None:
    headers = printed_tables((reports[kind] / "report.html").read_text()).headers
    for quantity in ("stator diameter", "stack length", "gear ratio", "reflected inertia", "peak torque"):
        units = set()
        for header in headers:
            if header.replace("_", " ").lower().startswith(quantity):
                units.update(re.findall(r"\[([^\]]+)\]$", header) or ["-"])
        units = {unit.replace("kg*m^2", "kg·m²").replace("N*m", "N·m") for unit in units}
        assert len(units) <= 1, (quantity, units)


@pytest.mark.parametrize("kind", PER_STUDY)
def test_no_local_path_in_the_report(reports: dict[str, Path], kind: str) -> None:
    html = (reports[kind] / "report.html").read_text()
    for folder in (ROOT, reports[kind], Path.home()):
        assert str(folder) not in html
    if "planar_two_link.urdf" in STUDIES[kind].read_text():
        assert "planar_two_link.urdf" in html  # the file is still named
