"""A run resolves its study once: its file is parsed once, and every piece of work receives the resolved study."""

from __future__ import annotations

import os
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import pytest

from collision_reflex.optimize.serial import SerialExecutor
from collision_reflex.study import load, source
from collision_reflex.study.problems import StudyProblems
from collision_reflex.study.resolve import ResolvedStudy
from collision_reflex.study.runner import run_study

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("executor", ["serial", "processes"])
def test_a_run_parses_its_study_once_and_its_workers_get_the_object(tmp_path, monkeypatch, executor):
    parent = os.getpid()
    parsed: list[str] = []
    parse = source.parse_study_source

    def counted(text, file="<string>", directory=None):
        # A worker (forked with this patch) must not parse: it has the study already.
        assert os.getpid() == parent, "a worker parsed the study's text"
        parsed.append(file)
        return parse(text, file, directory)

    monkeypatch.setattr(source, "parse_study_source", counted)  # what load_study reads a file with
    monkeypatch.setattr(load, "parse_study_source", counted)  # what parse_study reads text with
    received: list[object] = []
    pool = SerialExecutor if executor == "serial" else ProcessPoolExecutor
    submit = pool.submit

    def recorded(self, fn, /, *args, **kwargs):
        received.extend([*args, *kwargs.values()])
        return submit(self, fn, *args, **kwargs)

    monkeypatch.setattr(pool, "submit", recorded)
    study = ROOT / "studies" / "two_link_planetary.yaml"
    run = run_study(
        study, tmp_path / "out", quiet=True, smoke=True, executor=executor, workers=1, figures=False
    )
    assert parsed == [str(study)]  # once, in this process
    text = (run.folder / "study.resolved.yaml").read_text(encoding="utf-8")
    assert not any(isinstance(item, str) and item == text for item in received)
    studies = [item.study if isinstance(item, StudyProblems) else item for item in received]
    studies = [item for item in studies if isinstance(item, ResolvedStudy)]
    assert studies and all(item.text == text for item in studies)  # the object, as the run resolved it
