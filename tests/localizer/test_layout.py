"""The localizer's rooms: each subpackage has a face, imports only the floors below it, and takes
nothing private from another; the package face still hands users every name it did."""

import ast
import importlib
import tomllib
from pathlib import Path

import pytest

import localizer

ROOT = Path(localizer.__file__).parent
#: Each subpackage and the subpackages it may import, from the ground up.
FLOORS = {
    "geometry": set(),
    "solve": {"geometry"},
    "contact": {"geometry"},
    "chain": {"geometry", "solve"},
    "filters": {"geometry", "contact"},
}
#: Modules at the top that every subpackage may import: the shared types, errors and defaults.
SHARED = {"_types", "_errors", "_defaults"}


def _imports(path):
    """(level, module, names) of every ``from … import …`` in ``path``, wherever it stands."""
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            yield node.level, node.module or "", [a.name for a in node.names]


@pytest.mark.parametrize("sub", sorted(FLOORS))
def test_each_subpackage_has_a_face_that_defines_what_it_exports(sub):
    mod = importlib.import_module(f"localizer.{sub}")
    assert isinstance(mod.__all__, list) and mod.__all__
    assert len(set(mod.__all__)) == len(mod.__all__), f"localizer.{sub}.__all__ names a name twice"
    for name in mod.__all__:
        assert hasattr(mod, name), f"localizer.{sub}.__all__ names {name!r}, which it does not define"


@pytest.mark.parametrize("sub", sorted(FLOORS))
def test_a_subpackage_imports_only_the_floors_below_it_and_nothing_private_of_them(sub):
    for path in sorted((ROOT / sub).glob("*.py")):
        for level, module, names in _imports(path):
            assert not (level == 0 and module.split(".")[0] == "localizer"), f"{path.name}: localizer by name"
            if level <= 1:
                continue  # another library, or its own room
            assert level == 2, f"{path.name}: an import {level} levels up"
            head = module.split(".")[0]
            if head in SHARED:
                continue
            assert head in FLOORS[sub], f"{sub}/{path.name} imports localizer.{module}, not below {sub}"
            assert "." not in module, f"{sub}/{path.name} reaches into localizer.{module} behind its face"
            private = [n for n in names if n.startswith("_")]
            assert not private, f"{sub}/{path.name} imports private {private} from localizer.{head}"


def test_nothing_is_left_at_the_top_but_the_face_and_the_shared_modules():
    loose = {p.stem for p in ROOT.glob("*.py")} - {"__init__"} - SHARED
    assert not loose, f"modules outside the subpackages: {sorted(loose)}"


def test_every_subpackage_is_installed():
    meta = tomllib.loads((ROOT.parent / "pyproject.toml").read_text())
    packages = set(meta["tool"]["setuptools"]["packages"])
    missing = {f"localizer.{sub}" for sub in FLOORS} - packages
    assert not missing, f"pyproject.toml's packages lack {sorted(missing)}: a wheel would leave them out"


def test_the_package_face_hands_on_only_what_its_subpackages_export():
    for name in localizer.__all__:
        owner = getattr(localizer, name)
        homes = [sub for sub in FLOORS if name in importlib.import_module(f"localizer.{sub}").__all__]
        shared = any(hasattr(importlib.import_module(f"localizer.{m}"), name) for m in SHARED)
        assert homes or shared, f"localizer.{name} ({owner!r}) comes from no subpackage's face"
