"""The packages say what they export and that they are typed."""

import importlib
from pathlib import Path

import pytest

PACKAGES = (
    "localizer",
    "passivity",
    "sim2d",
    "driver",
    "driver.jaw",
    "driver.wheel",
    "driver.link",
    "driver.records",
    "driver.cli",
    "bench",
)


@pytest.mark.parametrize("name", PACKAGES)
def test_each_package_declares_its_exports_and_ships_py_typed(name):
    mod = importlib.import_module(name)
    assert isinstance(mod.__all__, list) and mod.__all__, f"{name} has no __all__"
    for attr in mod.__all__:
        assert hasattr(mod, attr), f"{name}.__all__ names {attr!r}, which it does not define"
    top = Path(mod.__file__).parent if "." not in name else None
    if top is not None:
        assert (top / "py.typed").is_file(), f"{name} ships no py.typed"
