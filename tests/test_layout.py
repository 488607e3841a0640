"""The rooms of the two large packages, by one rule: each room (a subpackage) has a face that defines
what it exports, imports only the rooms below it, only through their faces, and nothing private of
them; nothing stands at the top but the package's face and the modules every room shares; every room
is installed. The localizer's face still hands users every name it did."""

import ast
import importlib
import tomllib
from pathlib import Path

import pytest

import localizer

#: Per package: each room and the rooms it may import, from the ground up, and the top-level modules
#: every room may import.
HOUSES = {
    "localizer": (
        {
            "geometry": set(),
            "solve": {"geometry"},
            "contact": {"geometry"},
            "chain": {"geometry", "solve"},
            "filters": {"geometry", "contact"},
        },
        {"_types", "_errors", "_defaults"},
    ),
    "driver": (
        {
            "link": set(),
            "jaw": set(),
            "wheel": {"jaw"},
            "records": {"jaw", "wheel"},
            "cli": {"jaw", "wheel", "link", "records"},
        },
        {"rig", "blas", "warmup"},
    ),
}
#: Packages whose rooms may import a room below by the package's name (the command line's lazy imports);
#: the localizer's modules import each other only relatively.
BY_NAME = {"driver"}
ROOMS = [(package, room) for package, (floors, _) in HOUSES.items() for room in sorted(floors)]


def _root(package):
    return Path(importlib.import_module(package).__file__).parent


@pytest.mark.parametrize(("package", "room"), ROOMS)
def test_each_room_has_a_face_that_defines_what_it_exports(package, room):
    mod = importlib.import_module(f"{package}.{room}")
    assert isinstance(mod.__all__, list) and mod.__all__
    assert len(set(mod.__all__)) == len(mod.__all__), f"{package}.{room}.__all__ names a name twice"
    for name in mod.__all__:
        assert hasattr(mod, name), f"{package}.{room}.__all__ names {name!r}, which it does not define"


@pytest.mark.parametrize(("package", "room"), ROOMS)
def test_a_room_imports_only_the_rooms_below_it_through_their_faces_and_nothing_private(package, room):
    floors, shared = HOUSES[package]
    for path in sorted((_root(package) / room).glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, ast.ImportFrom):
                continue
            module = node.module or ""
            if node.level == 0 and module.split(".")[0] == package:
                assert package in BY_NAME, f"{room}/{path.name} imports {module} by name"
                parts = module.split(".")
                assert len(parts) == 2, f"{room}/{path.name} reaches into {module} behind its face"
                head = parts[1]
            elif node.level == 2:
                head = module.split(".")[0]
                assert "." not in module, f"{room}/{path.name} reaches into {package}.{module} behind its face"
            elif node.level > 2:
                raise AssertionError(f"{room}/{path.name}: an import {node.level} levels up")
            else:
                continue  # another library, or its own room
            if head in shared:
                continue
            assert head in floors[room], f"{room}/{path.name} imports {package}.{head}, not below {room}"
            private = [a.name for a in node.names if a.name.startswith("_")]
            assert not private, f"{room}/{path.name} imports private {private} from {package}.{head}"


@pytest.mark.parametrize("package", sorted(HOUSES))
def test_nothing_is_left_at_the_top_but_the_face_and_the_shared_modules(package):
    loose = {p.stem for p in _root(package).glob("*.py")} - {"__init__"} - HOUSES[package][1]
    assert not loose, f"{package}: modules outside the rooms: {sorted(loose)}"


def test_every_room_is_installed():
    meta = tomllib.loads((Path(localizer.__file__).parents[1] / "pyproject.toml").read_text())
    packages = set(meta["tool"]["setuptools"]["packages"])
    missing = {f"{package}.{room}" for package, room in ROOMS} - packages
    assert not missing, f"pyproject.toml's packages lack {sorted(missing)}: a wheel would leave them out"


def test_the_localizer_face_hands_on_only_what_its_rooms_export():
    floors, shared = HOUSES["localizer"]
    for name in localizer.__all__:
        homes = [room for room in floors if name in importlib.import_module(f"localizer.{room}").__all__]
        top = any(hasattr(importlib.import_module(f"localizer.{m}"), name) for m in shared)
        assert homes or top, f"localizer.{name} comes from no room's face"
