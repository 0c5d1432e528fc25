"""The suite's parallel grouping is in effect: the tests of an ``xdist_group`` share one pytest-xdist worker.

pytest-xdist's ``--dist loadgroup`` (``pyproject.toml``) sends every test of a group to one worker by adding the
group to the test's id; where that stops working (pytest 9.2, pytest-dev/pytest-xdist#1386) nothing fails, but
each group's expensive set-up runs once per worker. This test sees it.
"""

from __future__ import annotations

import os

import pytest

pytestmark = pytest.mark.xdist_group("test_parallel_groups")


def test_a_grouped_test_carries_its_group_under_loadgroup(request: pytest.FixtureRequest) -> None:
    if "PYTEST_XDIST_WORKER" not in os.environ or not request.config.getvalue("loadgroup"):
        pytest.skip("not run by pytest-xdist with --dist loadgroup")
    assert request.node.nodeid.endswith("@test_parallel_groups"), (
        f"{request.node.nodeid}: --dist loadgroup does not group (pytest-dev/pytest-xdist#1386); "
        "use a pytest the test extra allows"
    )
