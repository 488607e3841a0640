"""The Monte Carlo runner: reproducibility, resume, Dask, bad study files."""

import json
import math
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from bench.montecarlo import read_trials, run_study, wilson
from bench.study import StudyError, load_study

ROOT = Path(__file__).resolve().parents[2]


def study_file(tmp_path, trials=4, extra=""):
    f = tmp_path / "s.toml"
    f.write_text(f'''
name = "small"
parts = ["{ROOT / 'parts' / 'cam.json'}"]
rolls_deg = [20.0, 15.0]
method = "paper"
trials = {trials}
seed = 7
noise = "paper"
{extra}
''')
    return f


def table(out):
    rows = read_trials(Path(out) / "trials.csv")
    return sorted(({k: v for k, v in r.items() if k != "time_s"} for r in rows),
                  key=lambda r: (int(r["level"]), int(r["trial"])))


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("ref")
    study = load_study(study_file(tmp, extra='[sweep]\nparameter = "v2_noise"\nvalues = [0.0, 0.0006]'))
    run_study(study, tmp / "a", workers=1, progress=False)
    return study, table(tmp / "a"), tmp


def test_same_seed_same_table_twice_and_with_two_workers(reference):
    study, ref, tmp = reference
    assert len(ref) == 8 and {r["level"] for r in ref} == {"0", "1"}
    run_study(study, tmp / "b", workers=1, progress=False)
    run_study(study, tmp / "c", workers=2, progress=False)
    assert table(tmp / "b") == ref
    assert table(tmp / "c") == ref
    summary = json.loads((tmp / "c" / "summary.json").read_text())
    assert [lv["trials"] for lv in summary["levels"]] == [4, 4]
    for name in ("success.png", "errors.png", "failures.png"):
        assert (tmp / "c" / name).stat().st_size > 5000


def test_columns_of_the_contract(reference):
    _, ref, _ = reference
    for key in ("level", "trial", "error_mm", "success"):
        assert key in ref[0]


def test_resume_after_a_killed_run(tmp_path):
    f = study_file(tmp_path, trials=8)
    out = tmp_path / "run"
    cmd = [sys.executable, "-m", "bench.cli", "montecarlo", str(f), "--out", str(out), "--workers", "1"]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=ROOT)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and len(read_trials(out / "trials.csv")) < 3:
        time.sleep(0.1)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    partial = read_trials(out / "trials.csv")
    assert 3 <= len(partial) < 8
    rc = subprocess.run(cmd + ["--resume"], capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert rc.returncode == 0, rc.stderr
    rows = table(out)
    keys = [(r["level"], r["trial"]) for r in rows]
    assert len(keys) == 8 and len(set(keys)) == 8
    fresh = tmp_path / "fresh"
    run_study(load_study(f), fresh, workers=1, progress=False)
    assert rows == table(fresh)


def test_dask_local_cluster_gives_the_same_table(reference):
    distributed = pytest.importorskip("distributed")
    study, ref, tmp = reference
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None,
                                  processes=True) as cluster:
        run_study(study, tmp / "dask", scheduler=cluster.scheduler_address, progress=False)
    assert table(tmp / "dask") == ref


@pytest.mark.parametrize("text, match", [
    ('parts = ["nope.json"]\nrolls_deg = [20.0]', "part file .*nope.json does not exist"),
    ('parts = []\nrolls_deg = [20.0]', "'parts' must be a non-empty list"),
    ('parts = ["{cam}"]\nrolls_deg = [20.0, -15.0]', "one sign"),
    ('parts = ["{cam}"]\nrolls_deg = [20.0]\nmethod = "guess"', "method 'guess'"),
    ('parts = ["{cam}"]\nrolls_deg = [20.0]\ntrials = 0', "trials=0 must be an integer >= 1"),
    ('parts = ["{cam}"]\nrolls_deg = [20.0]\ncolour = 3', r"unknown key\(s\) \['colour'\]"),
    ('parts = ["{cam}"]\nrolls_deg = [20.0]\n[sweep]\nparameter = "v9"\nvalues = [1.0]', "not a noise-model field"),
    ('parts = ["{cam}"]\nrolls_deg = [20.0]\n[sweep]\nparameter = "v2_noise"\nvalues = [-1.0]', "must be >= 0"),
    ('parts = ["{cam}"]\nrolls_deg = [20.0]\nnoise = "lab"', "noise"),
    ('parts = [', "not valid TOML"),
    ('parts = ["{cam}"]\nrolls_deg = [20.0]\nmethods = ["paper", "oracle"]', "methods .* distinct names"),
    ('parts = ["{cam}"]\nrolls_deg = [20.0]\nmethod = "paper"\nmethods = ["paper"]', "not both"),
    ('parts = ["{cam}"]\nrolls_deg = [20.0]\nmethods = ["reactive"]\n[reactive]\nconfidence = 1.5',
     "confidence=1.5 must be below 1"),
    ('parts = ["{cam}"]\nrolls_deg = [20.0]\nmethods = ["particle"]\n[particle]\nspeed = 2', r"unknown key\(s\) \['speed'\]"),
])
def test_bad_study_files(tmp_path, text, match):
    f = tmp_path / "bad.toml"
    f.write_text(text.replace("{cam}", str(ROOT / "parts" / "cam.json")))
    with pytest.raises(StudyError, match=match):
        load_study(f)


def test_cli_reports_bad_study(tmp_path, capsys):
    from bench.cli import main

    assert main(["montecarlo", str(tmp_path / "missing.toml"), "--out", str(tmp_path / "o")]) == 2
    assert "cannot read" in capsys.readouterr().err


def test_wilson_interval():
    lo, hi = wilson(45, 100)
    assert lo == pytest.approx(0.355, abs=0.002) and hi == pytest.approx(0.548, abs=0.002)
    assert wilson(0, 10)[0] == 0.0


def test_shipped_studies_load():
    for name in ("paper", "arc_length", "rotation", "machining", "reactive", "filters"):
        s = load_study(ROOT / "bench" / "studies" / f"{name}.toml")
        assert s.trials > 0
    paper = load_study(ROOT / "bench" / "studies" / "paper.toml")
    assert paper.method == "paper" and paper.noise == "paper" and paper.rolls_deg == (20.0, 15.0)


def test_reactive_study_scores_three_methods_on_the_same_trials(tmp_path):
    from bench.cli import main

    out = tmp_path / "r"
    assert main(["montecarlo", str(ROOT / "bench" / "studies" / "reactive.toml"), "--out", str(out),
                 "--trials", "2", "--engine", "kinematic", "--workers", "1"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert set(summary["methods"]) == {"paper", "particle", "reactive"}
    assert all(0.0 <= r <= 1.0 for r in summary["methods"].values())
    rows = read_trials(out / "trials.csv")
    assert len(rows) == 2 and all(f"{m}_curve" in rows[0] for m in summary["methods"])
    for r in rows:  # the paper method's row is the study's own result
        assert r["success"] == r["paper_success"] and float(r["reactive_rotation_deg"]) > 0
    assert (out / "methods.png").exists()


def test_grid_method_scores_the_filter_on_the_fixed_readings(tmp_path):
    from bench.cli import main

    text = (ROOT / "bench" / "studies" / "filters.toml").read_text()
    text = text.replace("../../parts/", str(ROOT / "parts") + "/").replace("particles = 200000", "particles = 500")
    (tmp_path / "f.toml").write_text(text)
    out = tmp_path / "f"
    assert main(["montecarlo", str(tmp_path / "f.toml"), "--out", str(out), "--trials", "3", "--workers", "1"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert set(summary["methods"]) == {"paper", "particle", "grid"}
    rows = read_trials(out / "trials.csv")
    for r in rows:
        assert float(r["grid_rotation_deg"]) == pytest.approx(35.0)
        assert len(r["grid_curve"].split()) == 7                       # every 5° of the 35°
        # the filter was fed the same readings as the paper's rule: it lands where the truth is
        # or fails like a method, never as a broken trial
        assert r["failure"] == "" and math.isfinite(float(r["grid_error_mm"]))
