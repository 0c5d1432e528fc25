"""Start-up: ``import collision_reflex`` and ``crx`` load the heavy libraries only when a command needs them.

The public names are resolved on first access (PEP 562); these tests check that every name still resolves to
the object its defining module holds, and what a fresh interpreter has imported after each start-up. Timings
are printed by ``benchmarks/startup.py``, not asserted here.
"""

from __future__ import annotations

import ast
import importlib
import os
import subprocess
import sys
from pathlib import Path

import pytest

import collision_reflex as cr

ROOT = Path(__file__).resolve().parents[1]
HEAVY = ("casadi", "scipy", "pinocchio", "pandas", "matplotlib")


def imported_after(code: str, *, submodules: bool = False) -> set[str]:
    """The modules a fresh interpreter has in ``sys.modules`` after running ``code`` (top-level names only,
    unless ``submodules``)."""
    # The module list is the last line on stderr: the code may print on stdout.
    probe = f"{code}\nimport sys\nprint(' '.join(sys.modules), file=sys.stderr)"
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    done = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, check=True, env=env, cwd=ROOT
    )
    names = set(done.stderr.splitlines()[-1].split())
    return names if submodules else {name.split(".")[0] for name in names}


def test_import_loads_no_heavy_library():
    loaded = imported_after("import collision_reflex")
    assert "collision_reflex" in loaded
    assert not loaded & set(HEAVY), sorted(loaded & set(HEAVY))


def test_the_probe_sees_a_heavy_library_when_one_is_used():
    # The check above must be able to fail: touching a name whose module needs CasADi loads it.
    assert "casadi" in imported_after("import collision_reflex\ncollision_reflex.build_problem")


def test_crx_help_loads_no_heavy_library():
    loaded = imported_after("from collision_reflex.cli import main\nmain(['--help'])")
    assert not loaded & {*HEAVY, "pint", "pydantic"}, sorted(loaded & {*HEAVY, "pint", "pydantic"})


@pytest.mark.parametrize("flags", [["--schema-only"], []], ids=["schema-only", "with-robot"])
def test_crx_validate_loads_only_what_it_checks_with(flags):
    code = f"from collision_reflex.cli import main\nmain(['validate', *{flags!r}, 'studies/two_link_paper.yaml'])"
    loaded = imported_after(code)
    assert {"pydantic", "pint", "yaml"} <= loaded  # it did check the study and its units
    # pint imports Dask, SciPy and Babel when installed (pint.compat); crx hides them, and needs no solver,
    # plotting, table or template library.
    unused = {*HEAVY, "dask", "babel", "jinja2"} - ({"pinocchio"} if not flags else set())
    assert not loaded & unused, sorted(loaded & unused)
    assert ("pinocchio" in loaded) == (not flags)  # the robot is loaded only without --schema-only


def test_pint_without_its_extras_leaves_them_importable():
    # After crx's pint import the hidden libraries import normally, and pint works with NumPy arrays.
    pytest.importorskip("dask")
    pytest.importorskip("scipy")
    code = (
        "from collision_reflex import _units\n_units.hide_pint_extras()\n"
        "import numpy as np\nq = _units.unit_registry().Quantity(np.array([1.0, 2.0]), 'mm')\n"
        "assert list(q.to('m').magnitude) == [0.001, 0.002]\n"
        "import pint.compat, scipy, dask\nassert not pint.compat.HAS_DASK"
    )
    assert {"scipy", "dask"} <= imported_after(code)


def test_every_public_name_resolves_and_dir_lists_it():
    assert len(cr.__all__) == len(set(cr.__all__))
    for name in cr.__all__:
        assert getattr(cr, name) is not None, name
    assert set(cr.__all__) <= set(dir(cr))


def _type_checking_imports(package: str) -> dict[str, tuple[str, str]]:
    """The names the ``if TYPE_CHECKING:`` block of ``package`` (``collision_reflex``, ``...experiments``)
    imports: name -> (module, attribute)."""
    init = ROOT / "src" / Path(*package.split(".")) / "__init__.py"
    tree = ast.parse(init.read_text(encoding="utf-8"))
    block = next(n for n in tree.body if isinstance(n, ast.If) and ast.unparse(n.test) == "TYPE_CHECKING")
    names: dict[str, tuple[str, str]] = {}
    for node in block.body:
        assert isinstance(node, ast.ImportFrom) and node.level == 1
        for alias in node.names:
            names[alias.asname or alias.name] = (node.module or "", alias.name)
    return names


@pytest.mark.parametrize("package", ["collision_reflex.experiments"])
def test_the_type_checkers_names_are_the_run_time_names(package):
    # The TYPE_CHECKING imports (what mypy and IDEs see) and the lazy table must name the same objects.
    lazy = importlib.import_module(package)
    declared = _type_checking_imports(package)
    assert set(declared) == set(lazy.__all__) - {"__version__"}
    for name, (module, attribute) in declared.items():
        where = importlib.import_module(f"{package}.{module}" if module else package)
        assert getattr(where, attribute) is getattr(lazy, name), name


def test_the_duty_cycles_trace_units_do_not_load_the_experiment_fits():
    loaded = imported_after("import collision_reflex.arm.duty_cycle", submodules=True)
    assert "collision_reflex.experiments.traces" in loaded
    assert not {"collision_reflex.experiments.fit", "collision_reflex.experiments.analysis"} & loaded


def test_from_import_and_star_import_work():
    namespace: dict[str, object] = {}
    exec("from collision_reflex import *", namespace)
    assert set(cr.__all__) <= set(namespace)
    from collision_reflex import solve
    from collision_reflex.optimize import solve as optimize_solve

    assert solve is optimize_solve


def test_subpackages_are_attributes():
    assert cr.optimize.__name__ == "collision_reflex.optimize"
    assert cr.experiments.__name__ == "collision_reflex.experiments"


@pytest.mark.parametrize("name", ["not_a_name", "__wrapped__", "arm.not_a_module"])
def test_an_unknown_name_is_an_attribute_error(name):
    with pytest.raises(AttributeError, match=name):
        getattr(cr, name)
    assert not hasattr(cr, name)


def test_crx_help_lists_every_subcommand(capsys):
    from collision_reflex.cli import main

    assert main(["--help"]) == 0
    shown = capsys.readouterr().out
    for command in (
        "impulse",
        "motors",
        "sweep",
        "surface",
        "fit",
        "simulate",
        "validate",
        "schema",
        "run",
        "report",
    ):
        assert f"    {command} " in shown, command


def test_a_subcommand_is_parsed_without_importing_the_others():
    code = "from collision_reflex.cli import main\nmain(['validate', '--schema-only', 'studies/two_link_paper.yaml'])"
    loaded = imported_after(code, submodules=True)
    assert "collision_reflex.cli.validate" in loaded
    others = {
        "collision_reflex.cli.impulse",
        "collision_reflex.cli.sweep",
        "collision_reflex.hardware.sweeps",
    }
    assert not loaded & others, sorted(loaded & others)


@pytest.mark.parametrize("command", ["validate", "sweep", "run"])
def test_a_subcommands_help_is_the_same_alone(command, capsys):
    # `crx COMMAND --help` as parsed with that subcommand alone, and with every subcommand.
    from collision_reflex.cli import build_parser, main

    assert main([command, "--help"]) == 0
    alone = capsys.readouterr().out
    with pytest.raises(SystemExit):
        build_parser().parse_args([command, "--help"])
    assert capsys.readouterr().out == alone
    assert alone.startswith(f"usage: crx {command}")


@pytest.mark.parametrize(
    "arguments",
    [
        ["--help"],
        ["no-such-command"],
        ["validate", "studies/two_link_paper.yaml", "studies/two_link_paper.yaml"],
        ["validate", "studies/no_such_study.yaml"],
    ],
    ids=["help", "usage-error", "two-studies", "missing-study"],
)
@pytest.mark.parametrize("collecting", [True, False], ids=["gc-on", "gc-off"])
def test_main_leaves_the_garbage_collector_as_it_found_it(arguments, collecting, capsys):
    # crx's start-up runs without collection and freezes its objects; a Python caller gets its collector back.
    import gc

    from collision_reflex.cli import main

    assert gc.get_freeze_count() == 0
    (gc.enable if collecting else gc.disable)()
    try:
        main(arguments)
        assert gc.isenabled() == collecting
        assert gc.get_freeze_count() == 0
    finally:
        gc.enable()
    capsys.readouterr()


def test_the_crx_process_keeps_its_start_up_frozen():
    # The frozen start-up is walked by no collection, the last one at exit included; collection stays on.
    code = (
        "import gc, sys\nfrom collision_reflex.cli import main\n"
        "sys.argv = ['crx', 'validate', 'studies/two_link_paper.yaml']\nassert main() == 0\n"
        "print(gc.isenabled(), gc.get_freeze_count() > 10_000, file=sys.stderr)"
    )
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, env=env, cwd=ROOT
    )
    assert done.stderr.split() == ["True", "True"]
