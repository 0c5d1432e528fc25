"""PDF of the HTML report, printed by a headless Chromium (optional: only when a study asks for ``pdf: true``)."""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from pathlib import Path

from .._io import atomic_path
from ..errors import CollisionReflexError

BROWSERS = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")


class BrowserUnavailable(CollisionReflexError):
    """No headless Chromium (or Chrome) is installed to print the report."""


def find_browser() -> str | None:
    """Path of a Chromium-family browser, or None."""
    for name in BROWSERS:
        path = shutil.which(name)
        if path:
            return path
    return None


def headless_flags(profile: str) -> list[str]:
    """Flags for a headless, offline, throw-away browser session."""
    return [
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        f"--user-data-dir={profile}",
    ]


def html_to_pdf(html: Path, pdf: Path, timeout: float = 120.0) -> Path:
    """Print ``html`` to ``pdf`` (atomically) with headless Chromium."""
    browser = find_browser()
    if browser is None:
        raise BrowserUnavailable(
            "printing report.pdf needs Chromium or Chrome (e.g. apt-get install chromium)"
        )
    with tempfile.TemporaryDirectory() as profile, atomic_path(pdf) as tmp:
        completed = subprocess.run(
            [
                browser,
                *headless_flags(profile),
                "--no-pdf-header-footer",
                f"--print-to-pdf={tmp}",
                Path(html).resolve().as_uri(),
            ],
            capture_output=True,
            timeout=timeout,
            check=False,
        )
        if completed.returncode != 0 or not tmp.exists() or tmp.stat().st_size == 0:
            raise BrowserUnavailable(
                f"Chromium could not print the report (exit status {completed.returncode})"
            )
    return pdf
