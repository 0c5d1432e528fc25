"""The unit registry built through pint's on-disk cache (as the ``crx`` command builds it).

The cached registry must read every unit as the registry built without the cache, refuse the same texts with
the same messages, be built again when the definitions change or a cache file is damaged, work without a
usable folder, and write nothing outside its folder in the user's cache folder.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from pint.util import UnitsContainer

from collision_reflex import _units

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def definitions():
    found = _units.registry_definitions()
    assert found is not None
    return found


@pytest.fixture(scope="module")
def uncached(definitions):
    return _units.import_pint().UnitRegistry(definitions)


def _version_folder(folder: Path) -> Path:
    (found,) = folder.iterdir()
    return found


def test_a_cached_registry_reads_every_name_as_the_uncached_one(definitions, uncached, tmp_path):
    first = _units.cached_registry(definitions, tmp_path)  # builds the cache
    again = _units.cached_registry(definitions, tmp_path)  # reads it
    assert first is not None and again is not None
    assert len(list(_version_folder(tmp_path).glob("*.pickle"))) == 2
    assert set(again._prefixes) == set(uncached._prefixes)
    spellings = {name for p in uncached._prefixes.values() for name in (p.name, p.symbol, *p.aliases) if name}
    for registry in (first, again):
        for name in list(uncached._units):  # (a unit read with a prefix is added to the dict)
            assert registry.parse_unit_name(name) == uncached.parse_unit_name(name), name
            for prefix in spellings:
                text = prefix + name
                assert registry.parse_unit_name(text) == uncached.parse_unit_name(text), text
            unit = UnitsContainer({name: 1})
            assert registry.get_dimensionality(unit) == uncached.get_dimensionality(unit), name
            for method in ("get_root_units", "get_base_units"):
                (mine, mine_units), (theirs, their_units) = (
                    getattr(r, method)(unit) for r in (registry, uncached)
                )
                assert mine == theirs and mine_units._units == their_units._units, (method, name)
        assert registry.default_system == uncached.default_system


# Read, refused and converted texts: quantities of the datasheets, offset units, wrong dimensions, unknown names.
TEXTS = [
    ("60 mm", "m"),
    ("1.3 N*m", "N*m"),
    ("2.21e-5 kg*m^2", "kg*m**2"),
    ("3000 rpm", "rad/s"),
    ("50 Hz", "rad/s"),
    ("1 ozf*in", "N*m"),
    ("4096 counts/rev", "1/rad"),
    ("20 degC", "K"),
    ("3 kg", "N*m/rad"),
    ("1 kt", "m/s"),
    ("1 statvolt", "V"),
    ("1 furlong", "m"),
    ("1 deg*degC", "K"),
]
PROBE = """
import json, sys
from collision_reflex import _units
if sys.argv[1] == "cached":
    _units.cache_registry()
out = []
for text, unit in json.loads(sys.argv[2]):
    try:
        out.append(repr(_units.parse_quantity(text, unit, angle_explicit=unit == "rad/s")))
    except _units.QuantityError as error:
        out.append(f"{error.kind}: {error}")
print(json.dumps(out))
"""


def _parsed(mode: str, cache_home: Path) -> list[str]:
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "XDG_CACHE_HOME": str(cache_home)}
    done = subprocess.run(
        [sys.executable, "-c", PROBE, mode, json.dumps(TEXTS)],
        capture_output=True,
        text=True,
        check=True,
        env=env,
        cwd=ROOT,
    )
    return json.loads(done.stdout)


def test_the_cached_registry_gives_the_same_numbers_and_refusals(tmp_path):
    expected = _parsed("uncached", tmp_path)
    assert not (tmp_path / "collision-reflex").exists()  # a library user's registry writes nothing
    assert _parsed("cached", tmp_path) == expected  # building the cache
    assert _parsed("cached", tmp_path) == expected  # reading it
    assert (tmp_path / "collision-reflex" / "units").is_dir()
    assert sum(text.startswith(("unit:", "dimension:", "angle:")) for text in expected) >= 4


def test_changed_definitions_get_their_own_cache(definitions, tmp_path):
    assert _units.cached_registry(definitions, tmp_path).parse_unit_name("smoot") == ()
    changed = _units.cached_registry([*definitions, "smoot = 1.7018 m"], tmp_path)
    assert changed.Quantity(1.0, "smoot").to("m").magnitude == 1.7018
    assert _units.cached_registry(definitions, tmp_path).parse_unit_name("smoot") == ()
    assert len(list(_version_folder(tmp_path).glob("definitions-*.txt"))) == 2


@pytest.mark.parametrize("damage", [b"", b"not a pickle", b"\x80\x05\x95"], ids=["empty", "garbage", "cut"])
def test_a_damaged_cache_is_built_again(definitions, uncached, tmp_path, damage):
    _units.cached_registry(definitions, tmp_path)
    folder = _version_folder(tmp_path)
    for pickle in folder.glob("*.pickle"):
        pickle.write_bytes(damage)
    registry = _units.cached_registry(definitions, tmp_path)
    assert registry is not None
    assert (
        registry.Quantity(1.0, "lbf*ft").to("N*m").magnitude
        == uncached.Quantity(1.0, "lbf*ft").to("N*m").magnitude
    )
    pickles = list(folder.glob("*.pickle"))
    assert len(pickles) == 2 and all(p.stat().st_size > 100 for p in pickles)


def test_a_changed_definitions_file_is_written_again(definitions, tmp_path):
    _units.cached_registry(definitions, tmp_path)
    (path,) = _version_folder(tmp_path).glob("definitions-*.txt")
    path.write_text("metre = [length]\n", encoding="utf-8")
    registry = _units.cached_registry(definitions, tmp_path)
    assert registry.Quantity(1.0, "lbf").to("N").magnitude == pytest.approx(4.4482216152605)
    assert path.read_text(encoding="utf-8") == "\n".join(definitions) + "\n"


def test_no_usable_folder_means_no_cache(definitions, tmp_path, monkeypatch):
    assert _units.cached_registry(definitions, None) is None
    blocked = tmp_path / "a file"
    blocked.write_text("", encoding="utf-8")
    assert _units.cached_registry(definitions, blocked / "units") is None  # cannot be created
    monkeypatch.setattr(os, "access", lambda path, mode: False)  # read-only (root may write anyway)
    assert _units.cached_registry(definitions, tmp_path / "units") is None
    assert not [path for path in (tmp_path / "units").rglob("*") if path.is_file()]


def test_crx_writes_only_in_the_users_cache_folder(tmp_path):
    home = tmp_path / "home"
    home.mkdir()
    env = {name: value for name, value in os.environ.items() if name != "XDG_CACHE_HOME"}
    env.update(HOME=str(home), PYTHONPATH=str(ROOT / "src"), PYTHONDONTWRITEBYTECODE="1")
    command = [sys.executable, "-m", "collision_reflex", "validate", "studies/two_link_paper.yaml"]
    before = {path for path in ROOT.rglob("*") if "__pycache__" not in path.parts}
    for _ in range(2):  # builds the cache, then reads it
        done = subprocess.run(command, capture_output=True, text=True, env=env, cwd=ROOT)
        assert done.returncode == 0, done.stderr
        assert "valid" in done.stdout
    written = sorted(str(path.relative_to(home)) for path in home.rglob("*") if path.is_file())
    assert written and all(name.startswith(".cache/collision-reflex/units/") for name in written), written
    assert {path for path in ROOT.rglob("*") if "__pycache__" not in path.parts} == before


def test_crx_works_without_a_cache_folder(tmp_path):
    blocked = tmp_path / "a file"
    blocked.write_text("", encoding="utf-8")
    env = {**os.environ, "XDG_CACHE_HOME": str(blocked), "PYTHONPATH": str(ROOT / "src")}
    command = [sys.executable, "-m", "collision_reflex", "validate", "studies/two_link_paper.yaml"]
    done = subprocess.run(command, capture_output=True, text=True, env=env, cwd=ROOT)
    assert done.returncode == 0, done.stderr
    assert blocked.read_text(encoding="utf-8") == ""
