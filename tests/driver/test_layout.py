"""The driver's rooms: the straight jaw, the wheel, the serial link and the records each have a face,
import only the rooms below them (and the rig they all drive) and take nothing private of another."""

import ast
import importlib
from pathlib import Path

import pytest

import driver

ROOT = Path(driver.__file__).parent
#: Each room and the rooms it may import, from the ground up.
FLOORS = {
    "link": set(),
    "jaw": set(),
    "wheel": {"jaw"},
    "records": {"jaw", "wheel"},
    "cli": {"jaw", "wheel", "link", "records"},
}
#: Modules at the top that every room may import: the rig's protocol and records.
SHARED = {"rig"}


@pytest.mark.parametrize("room", sorted(FLOORS))
def test_each_room_has_a_face_that_defines_what_it_exports(room):
    mod = importlib.import_module(f"driver.{room}")
    assert isinstance(mod.__all__, list) and mod.__all__
    assert len(set(mod.__all__)) == len(mod.__all__), f"driver.{room}.__all__ names a name twice"
    for name in mod.__all__:
        assert hasattr(mod, name), f"driver.{room}.__all__ names {name!r}, which it does not define"


@pytest.mark.parametrize("room", sorted(FLOORS))
def test_a_room_imports_only_the_rooms_below_it_through_their_faces(room):
    for path in sorted((ROOT / room).glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, ast.ImportFrom):
                continue
            module = node.module or ""
            if node.level == 0 and module.split(".")[0] == "driver":
                parts = module.split(".")
                assert len(parts) == 2, f"{room}/{path.name} reaches into {module} behind its face"
                head = parts[1]
            elif node.level == 2:
                head = module.split(".")[0]
                assert "." not in module, f"{room}/{path.name} reaches into driver.{module} behind its face"
            else:
                continue  # another library, or its own room
            if head in SHARED:
                continue
            assert head in FLOORS[room], f"{room}/{path.name} imports driver.{head}, not below {room}"
            private = [a.name for a in node.names if a.name.startswith("_")]
            assert not private, f"{room}/{path.name} imports private {private} from driver.{head}"


def test_nothing_is_left_at_the_top_but_the_face_and_the_rig():
    loose = {p.stem for p in ROOT.glob("*.py")} - {"__init__"} - SHARED
    assert not loose, f"modules outside the rooms: {sorted(loose)}"
