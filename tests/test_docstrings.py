"""Every public function's parameters are documented (after python-control's docstrings test).

Public: named in a package's ``__all__``, and the public methods of the classes there. A
parameter is documented when its docstring (for a class: the class's and ``__init__``'s) has a
numpy-style entry for it (``name : type``, or several names on one line) or names it in double
backquotes in the text (``name``), which the short one-line docstrings do.
"""

import importlib
import inspect
import re

import pytest

PACKAGES = ("localizer", "passivity", "sim2d", "driver", "bench")
_ENTRY = re.compile(r"^\s*([A-Za-z_]\w*(?:\s*,\s*[A-Za-z_]\w*)*)\s*(?::|$)")


def _documented(doc: str) -> set:
    names = set()
    for line in doc.splitlines():
        m = _ENTRY.match(line)
        if m:
            names.update(n.strip() for n in m.group(1).split(","))
        names.update(re.findall(r"``(\w+)``", line))
    return names


def _public_callables():
    for package in PACKAGES:
        mod = importlib.import_module(package)
        for name in mod.__all__:
            obj = getattr(mod, name)
            if inspect.isclass(obj):
                if issubclass(obj, BaseException):
                    continue
                init = obj.__dict__.get("__init__")
                if init is not None and inspect.isfunction(init):
                    yield f"{package}.{name}", init, (obj.__doc__ or "") + (init.__doc__ or "")
                elif hasattr(obj, "__dataclass_fields__"):
                    yield f"{package}.{name}", obj, obj.__doc__ or ""
                for attr, member in vars(obj).items():
                    if not attr.startswith("_") and inspect.isfunction(member):
                        yield f"{package}.{name}.{attr}", member, member.__doc__ or ""
            elif inspect.isfunction(obj):
                yield f"{package}.{name}", obj, obj.__doc__ or ""


def _params(fn) -> list:
    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):
        return []
    return [
        p.name
        for p in sig.parameters.values()
        if p.name not in ("self", "cls")
        and not p.name.startswith("_")
        and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)
    ]


CASES = list(_public_callables())


def test_there_is_something_to_check():
    assert len(CASES) > 100


@pytest.mark.parametrize("qualname, fn, doc", CASES, ids=[c[0] for c in CASES])
def test_every_parameter_is_documented(qualname, fn, doc):
    assert doc.strip(), f"{qualname} has no docstring"
    missing = [p for p in _params(fn) if p not in _documented(doc)]
    assert not missing, f"{qualname}: parameters not documented: {missing}"
