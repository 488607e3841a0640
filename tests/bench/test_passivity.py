"""The interface of ``python -m bench.reports.passivity --json``."""

import json
import subprocess
import sys


def test_json_gives_noise_and_min_energy_for_the_four_variants():
    out = subprocess.run(
        [sys.executable, "-m", "bench.reports.passivity", "--json"],
        capture_output=True,
        text=True,
        check=True,
        timeout=120,
    ).stdout
    result = json.loads(out)
    assert set(result) == {"plain", "sign_fix", "hold_fix", "both"}
    for r in result.values():
        assert isinstance(r["noise"], float) and isinstance(r["min_energy"], float)
    assert result["plain"]["noise"] > 10 * result["both"]["noise"]
