"""The README's Python examples run, and its two set-up commands exist."""

from __future__ import annotations

import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def _blocks(language: str) -> list[str]:
    return re.findall(rf"```{language}\n(.*?)```", README.read_text(), flags=re.S)


def test_python_examples_run(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # examples that write files write them here
    namespace: dict = {}
    blocks = _blocks("python")
    assert blocks, "the README has no Python examples"
    for block in blocks:  # blocks build on each other, as a reader would run them
        exec(compile(block, str(README), "exec"), namespace)


def test_two_setup_commands():
    commands = "\n".join(_blocks("bash"))
    assert 'pip install -e ".[test]" && python3 -m pytest' in commands
    assert re.search(r"pip install -e \. && crx ", commands)
