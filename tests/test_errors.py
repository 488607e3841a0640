"""One error root: every error class a package exports is a RolltouchError and a built-in error."""

import importlib

import pytest

from localizer import RolltouchError

PACKAGES = ("localizer", "passivity", "sim2d", "driver", "bench")
BUILTIN = (ValueError, OSError)


def _exported_errors():
    found = []
    for name in PACKAGES:
        mod = importlib.import_module(name)
        for attr in getattr(mod, "__all__", ()):
            obj = getattr(mod, attr)
            if isinstance(obj, type) and issubclass(obj, BaseException):
                found.append((name, attr, obj))
    return found


def test_packages_export_their_errors():
    names = {attr for _, attr, _ in _exported_errors()}
    assert {
        "RolltouchError",
        "PartError",
        "QueryError",
        "SimError",
        "RigError",
        "ProtocolError",
        "ControlError",
        "StudyError",
    } <= names


@pytest.mark.parametrize("package, name, cls", _exported_errors(), ids=lambda v: v if isinstance(v, str) else "")
def test_every_exported_error_is_ours_and_a_builtin_kind(package, name, cls):
    assert issubclass(cls, RolltouchError), f"{package}.{name} is not under RolltouchError"
    if cls is not RolltouchError:
        assert issubclass(cls, BUILTIN), f"{package}.{name} subclasses no matching built-in"
