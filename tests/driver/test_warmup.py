"""The localizer's compiled kernels, compiled by one call after an install (``make`` makes it)."""

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

# in a process of its own: in this one, earlier tests may have compiled the kernels already
PROBE = """
import importlib, json, pkgutil
import localizer, driver
driver.compile_kernels()
kernels = {}
for info in pkgutil.walk_packages(localizer.__path__, "localizer."):
    if info.name.endswith("_kernels"):
        module = importlib.import_module(info.name)
        for name in module.__all__:
            kernel = getattr(module, name)
            if hasattr(kernel, "signatures"):
                kernels[f"{info.name}.{name}"] = len(kernel.signatures)
print(json.dumps(kernels))
"""


def test_every_kernel_of_the_localizer_is_compiled_by_the_warm_up():
    out = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert out.returncode == 0, out.stderr
    kernels = json.loads(out.stdout.splitlines()[-1])
    assert len(kernels) >= 12  # the solver's, the chain's, the reach's, the tracks', the filter's, the Bézier's
    assert not [name for name, compiled in kernels.items() if not compiled]
