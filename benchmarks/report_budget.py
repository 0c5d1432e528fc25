"""The length of each run's report: words a reader sees in report.html, words and pages of report.pdf.

Usage: python benchmarks/report_budget.py RUN_DIR [RUN_DIR ...] (after crx run STUDY --out RUN_DIR); prints
a Markdown table and exits with status 1 if a report is over the budget: 2,500 words, 8 printed pages. The
tests hold the smoke run of every shipped study to it; this holds the full-size runs of every study to it.
"""

from __future__ import annotations

import os
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

from collision_reflex.cli import main


class Words(HTMLParser):
    """The words of the page outside style, script and figures."""

    def __init__(self) -> None:
        super().__init__()
        self.words: list[str] = []
        self.skip = 0

    def handle_starttag(self, tag, attrs):
        self.skip += tag in ("style", "script", "svg")

    def handle_endtag(self, tag):
        self.skip -= tag in ("style", "script", "svg")

    def handle_data(self, data):
        if not self.skip:
            self.words += data.split()


WORDS, PAGES = 2500, 8
over = []
print(f"load average {os.getloadavg()[0]:.2f}")
print("| run | HTML words | PDF words | PDF pages |\n|---|---|---|---|")
for folder in map(Path, sys.argv[1:]):
    main(["report", str(folder), "--pdf"])
    parser = Words()
    parser.feed((folder / "report.html").read_text())
    text = subprocess.run(
        ["pdftotext", "-layout", str(folder / "report.pdf"), "-"], capture_output=True, text=True, check=True
    ).stdout
    words, pages = max(len(parser.words), len(text.split())), text.count(chr(12))
    print(f"| {folder.name} | {len(parser.words):,} | {len(text.split()):,} | {pages} |")
    if words > WORDS or pages > PAGES:
        over.append(folder.name)
if over:
    print(f"over the budget ({WORDS} words, {PAGES} pages): " + ", ".join(over))
    sys.exit(1)
