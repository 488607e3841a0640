"""The Monte Carlo runner: reproducibility, resume, Dask, bad study files."""

import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bench.montecarlo import read_trials, run_study
from bench.scoring import parse_curve
from bench.study import StudyError, load_study
from bench.summary import wilson

from ..ctrl_c import CLI

ROOT = Path(__file__).resolve().parents[2]


def study_file(tmp_path, trials=4, extra=""):
    f = tmp_path / "s.toml"
    f.write_text(f'''
name = "small"
parts = ["{ROOT / "parts" / "cam.json"}"]
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
    return sorted(
        ({k: v for k, v in r.items() if k != "time_s"} for r in rows), key=lambda r: (int(r["level"]), int(r["trial"]))
    )


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


def test_resume_after_a_killed_run(tmp_path, capsys):
    from driver.cli import main

    f = study_file(tmp_path, trials=8)
    out = tmp_path / "run"
    args = ["montecarlo", str(f), "--out", str(out), "--workers", "1"]
    # the run to kill is a process of its own; the resume is the command as any other, run in this process
    cmd = [sys.executable, "-m", "driver.cli", *args]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=ROOT)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and len(read_trials(out / "trials.csv")) < 3:
        time.sleep(0.1)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    partial = read_trials(out / "trials.csv")
    assert 3 <= len(partial) < 8
    assert main([*args, "--resume"]) == 0, capsys.readouterr().err
    rows = table(out)
    keys = [(r["level"], r["trial"]) for r in rows]
    assert len(keys) == 8 and len(set(keys)) == 8
    fresh = tmp_path / "fresh"
    run_study(load_study(f), fresh, workers=1, progress=False)
    assert rows == table(fresh)


def test_dask_local_cluster_gives_the_same_table(reference):
    distributed = pytest.importorskip("distributed")
    study, ref, tmp = reference
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None, processes=True) as cluster:
        run_study(study, tmp / "dask", scheduler=cluster.scheduler_address, progress=False)
    assert table(tmp / "dask") == ref


@pytest.mark.parametrize(
    "text, match",
    [
        ('parts = ["nope.json"]\nrolls_deg = [20.0]', "part file .*nope.json does not exist"),
        ('parts = ["."]\nrolls_deg = [20.0]', "part file .* is a folder, not a part file"),
        ("parts = []\nrolls_deg = [20.0]", "'parts' must be a non-empty list"),
        ('parts = ["{cam}"]\nrolls_deg = [20.0, -15.0]', "one sign"),
        ('parts = ["{cam}"]\nrolls_deg = [20.0]\nmethod = "guess"', "method 'guess'"),
        ('parts = ["{cam}"]\nrolls_deg = [20.0]\ntrials = 0', "trials=0 must be an integer >= 1"),
        ('parts = ["{cam}"]\nrolls_deg = [20.0]\ntrials = true', "trials=True must be an integer >= 1"),
        ('parts = ["{cam}"]\nrolls_deg = [true]', "nonzero angles of one sign"),
        (
            'parts = ["{cam}"]\nrolls_deg = [20.0]\nmethods = ["reactive"]\n[reactive]\ndefect_window = false',
            "defect_window=False must be a positive number",
        ),
        (
            'parts = ["{cam}"]\nrolls_deg = [20.0]\nmethods = ["reactive"]\n[reactive]\nstretch_weight = 1.5',
            r"stretch_weight=1.5 must be a probability in \[0, 1\]",
        ),
        (
            'parts = ["{cam}"]\nrolls_deg = [20.0]\nmethods = ["reactive"]\n[reactive]\nstretch_weight = true',
            "stretch_weight=True must be a probability",
        ),
        (
            'parts = ["{cam}"]\nrolls_deg = [20.0]\nmethods = ["reactive"]\n[reactive]\noff_scale = 1.0',
            r"off_scale=1.0 must be a probability in \[0, 1\)",
        ),
        (
            'parts = ["{cam}"]\nrolls_deg = [20.0]\nmethods = ["reactive"]\n[reactive]\ncheck_every = 2.5',
            "check_every=2.5 must be a whole number",
        ),
        ('parts = ["{cam}"]\nrolls_deg = [20.0]\ncolour = 3', r"unknown key\(s\) \['colour'\]"),
        ('parts = ["{cam}"]\nrolls_deg = [20.0]\n[sweep]\nparameter = "v9"\nvalues = [1.0]', "not a noise-model field"),
        ('parts = ["{cam}"]\nrolls_deg = [20.0]\n[sweep]\nparameter = "v2_noise"\nvalues = [-1.0]', "must be >= 0"),
        ('parts = ["{cam}"]\nrolls_deg = [20.0]\nnoise = "lab"', "noise"),
        ("parts = [", "not valid TOML"),
        ('parts = ["{cam}"]\nrolls_deg = [20.0]\nstep_deg = 1e-9', r"step_deg=1e-09 must be between 0.01° and 5°"),
        ('parts = ["{cam}"]\nrolls_deg = [20.0]\ntrials = 10000000', "more than 100000"),
        ('parts = ["{cam}"]\nrolls_deg = [20.0]\nmethods = ["paper", "oracle"]', "methods .* distinct names"),
        ('parts = ["{cam}"]\nrolls_deg = [20.0]\nmethod = "paper"\nmethods = ["paper"]', "not both"),
        (
            'parts = ["{cam}"]\nrolls_deg = [20.0]\nmethods = ["reactive"]\n[reactive]\nconfidence = 1.5',
            "confidence=1.5 must be below 1",
        ),
        (
            'parts = ["{cam}"]\nrolls_deg = [20.0]\nmethods = ["particle"]\n[particle]\nspeed = 2',
            r"unknown key\(s\) \['speed'\]",
        ),
        (
            'parts = ["{cam}"]\nrolls_deg = [20.0]\nmethods = ["particle"]\n[particle]\nparticles = 1000000000',
            r"particles=1000000000 must be from 2 to 262144",
        ),
        ('parts = ["{cam}"]\nrolls_deg = [20.0]\n[world]\nburrs = 1', r"\[world\] unknown key\(s\) \['burrs'\]"),
        ('parts = ["{cam}"]\nrolls_deg = [20.0]\n[world]\nscale = 3.0', r"\[world\] scale=3.0 must be within"),
        (
            'parts = ["{cam}"]\nrolls_deg = [20.0]\n[world]\nworld_parts = ["{cam}", "{cam}"]',
            r"world_parts has 2 file\(s\) for 1 part\(s\)",
        ),
    ],
)
def test_bad_study_files(tmp_path, text, match):
    f = tmp_path / "bad.toml"
    f.write_text(text.replace("{cam}", str(ROOT / "parts" / "cam.json")))
    with pytest.raises(StudyError, match=match):
        load_study(f)


def test_cli_reports_bad_study(tmp_path, capsys):
    from driver.cli import main

    assert main(["montecarlo", str(tmp_path / "missing.toml"), "--out", str(tmp_path / "o")]) == 2
    assert "cannot read" in capsys.readouterr().err


def test_wilson_interval():
    lo, hi = wilson(45, 100)
    assert lo == pytest.approx(0.355, abs=0.002) and hi == pytest.approx(0.548, abs=0.002)
    assert wilson(0, 10)[0] == 0.0


@settings(max_examples=300, deadline=None)
@given(st.integers(1, 2000).flatmap(lambda n: st.tuples(st.integers(0, n), st.just(n))))
def test_the_wilson_interval_holds_the_rate_itself(case):
    # at 100/100 rounding once put the upper end below 1.0, and the study's plot refused the error bar
    k, n = case
    lo, hi = wilson(k, n)
    assert 0.0 <= lo <= k / n <= hi <= 1.0


def test_shipped_studies_load():
    for name in (
        "paper",
        "arc_length",
        "rotation",
        "machining",
        "reactive",
        "filters",
        "tuning",
        "heldout",
        "heldout-a",
    ):
        s = load_study(ROOT / "bench" / "studies" / f"{name}.toml")
        assert s.trials > 0
    paper = load_study(ROOT / "bench" / "studies" / "paper.toml")
    assert paper.method == "paper" and paper.noise == "paper" and paper.rolls_deg == (20.0, 15.0)


def test_reactive_study_scores_three_methods_on_the_same_trials(tmp_path):
    from driver.cli import main

    out = tmp_path / "r"
    assert (
        main(
            [
                "montecarlo",
                str(ROOT / "bench" / "studies" / "reactive.toml"),
                "--out",
                str(out),
                "--trials",
                "2",
                "--engine",
                "kinematic",
                "--workers",
                "1",
            ]
        )
        == 0
    )
    summary = json.loads((out / "summary.json").read_text())
    assert set(summary["methods"]) == {"paper", "particle", "reactive"}
    assert all(0.0 <= r <= 1.0 for r in summary["methods"].values())
    rows = read_trials(out / "trials.csv")
    assert len(rows) == 2 and all(f"{m}_curve" in rows[0] for m in summary["methods"])
    for r in rows:  # the paper method's row is the study's own result
        assert r["success"] == r["paper_success"] and float(r["reactive_rotation_deg"]) > 0
        assert r["paper_stopped"] == "fixed" and r["reactive_stopped"] in ("confident", "budget", "ambiguous")
        assert 0.0 <= float(r["reactive_mass"]) <= 1.0 and int(r["reactive_bridges"]) >= 0
        # each method's bound from its own readings: the reactive rolling reads more, so bounds less
        bounds = {m: float(r[f"{m}_bound_mm"]) for m in summary["methods"]}
        assert all(0 < b < 10 for b in bounds.values()), bounds
        assert bounds["paper"] == bounds["particle"] and bounds["reactive"] < bounds["paper"]
    for m, d in summary["method_details"].items():
        ok = [r for r in rows if int(r[f"{m}_success"])]
        assert d["bounded_successes"] == len(ok)
        ratios = [float(r[f"{m}_error_mm"]) / float(r[f"{m}_bound_mm"]) for r in ok]
        assert d["error_over_bound_rms"] == (pytest.approx(np.sqrt(np.mean(np.square(ratios)))) if ok else None)
    assert (out / "methods.png").exists() and (out / "bound.png").stat().st_size > 5000


def test_grid_method_scores_the_filter_on_the_fixed_readings(tmp_path):
    from driver.cli import main

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
        assert len(r["grid_curve"].split()) == 7  # every 5° of the 35°
        for m in ("paper", "particle", "grid"):
            # each mark of the error curve has the stated probability at that mark, the last one the final
            errors, masses = parse_curve(r[f"{m}_curve"]), parse_curve(r[f"{m}_mass_curve"])
            assert [k for k, _ in masses] == [k for k, _ in errors]
            assert all(0.0 <= p <= 1.0 + 1e-9 for _, p in masses)
            assert masses[-1][1] == pytest.approx(float(r[f"{m}_mass"]), abs=1e-5)
        # the filter was fed the same readings as the paper's rule: it lands where the truth is
        # or fails like a method, never as a broken trial
        assert r["failure"] == "" and math.isfinite(float(r["grid_error_mm"]))


def small_methods_study(tmp_path, extra=""):
    f = tmp_path / "m.toml"
    f.write_text(f'''
name = "methods"
parts = ["{ROOT / "parts" / "cam.json"}"]
rolls_deg = [20.0, 15.0]
methods = ["paper", "particle", "grid"]
trials = 2
seed = 3
noise = "paper"
[particle]
particles = 500
{extra}
''')
    return load_study(f)


@pytest.fixture
def paper_rule_refuses(monkeypatch):
    """The localizer's paper rule refuses every query (the other rules as they are)."""
    import localizer

    real = localizer.localize

    def paper_breaks(part, rolls, rule="likelihood", **kw):
        if rule == "paper":
            raise localizer.QueryError("length=-15.875 mm must be in (0, perimeter)")
        return real(part, rolls, rule=rule, **kw)

    monkeypatch.setattr(localizer, "localize", paper_breaks)


def test_one_methods_error_is_that_methods_failure_only(tmp_path, paper_rule_refuses):
    from bench.trial import TrialSpec, run_trial

    study = small_methods_study(tmp_path)
    row = run_trial(TrialSpec(study, 0, 0))
    assert row["failure"] == ""  # the trial itself did not break
    assert row["paper_stopped"] == "error" and row["paper_success"] == 0
    assert row["paper_failure"].startswith("QueryError: length=-15.875")
    for m in ("particle", "grid"):
        assert row[f"{m}_stopped"] == "fixed" and row[f"{m}_failure"] == ""
        assert math.isfinite(row[f"{m}_error_mm"]) and 0.0 <= row[f"{m}_mass"] <= 1.0


def test_summary_is_strict_json_with_the_per_method_record(tmp_path):
    study = small_methods_study(tmp_path)
    run_study(study, tmp_path / "out", workers=1, progress=False)

    def refuse(name):
        raise ValueError(f"{name} is not JSON")

    summary = json.loads((tmp_path / "out" / "summary.json").read_text(), parse_constant=refuse)
    for m in study.methods:
        d = summary["method_details"][m]
        assert d["confident"] == 0 and d["confident_wrong"] == 0  # fixed rolls never stop sure
        assert d["per_part"] == {"cam.json": {"success": d["success"], "trials": 2}}
    rows = read_trials(tmp_path / "out" / "trials.csv")
    for r in rows:
        for m in study.methods:
            assert r[f"{m}_stopped"] == "fixed" and r[f"{m}_failure"] == ""
    assert (tmp_path / "out" / "reliability.png").stat().st_size > 5000


def test_a_noise_sweep_runs_each_level_on_its_noise_file(tmp_path):
    (tmp_path / "loud.toml").write_text('preset = "paper"\nv2_noise = 0.0004\n')
    sweep = '[sweep]\nparameter = "noise"\nvalues = ["paper", "loud.toml"]'
    study = load_study(study_file(tmp_path, trials=1, extra=sweep))
    assert study.levels == 2 and [study.level_label(k) for k in range(2)] == ["paper", "loud"]
    assert study.level_noise(1).v2_noise == 0.0004 and study.level_noise(0).v2_noise == 0.0001
    run_study(study, tmp_path / "o", workers=1, progress=False)
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert [lv["value"] for lv in summary["levels"]] == ["paper", "loud"]
    with pytest.raises(StudyError, match="sweep noise 'nope'"):
        load_study(study_file(tmp_path, extra='[sweep]\nparameter = "noise"\nvalues = ["nope"]'))


def test_a_reactive_table_without_standard_deviations_uses_the_filters_own(tmp_path):
    from bench.reactive_method import reactive_filter
    from localizer import NOISE_SCALES, ContactFilter, load_part
    from sim2d import load_noise

    study = small_methods_study(tmp_path, extra="[reactive]\nconfidence = 0.9")
    flt = reactive_filter(study, load_part(ROOT / "parts" / "cam.json"), load_noise("paper"))
    default = ContactFilter(flt.part)
    assert (flt.sd_position, flt.sd_scale, flt.sd_slope) == (default.sd_position, default.sd_scale, default.sd_slope)
    assert flt.noise_scales == NOISE_SCALES and flt.confidence == 0.9
    pinned = small_methods_study(tmp_path, extra='[reactive]\nnoise_scales = [1.0]\nsd_slope = "auto"')
    assert reactive_filter(pinned, flt.part, load_noise("paper")).noise_scales == (1.0,)
    with pytest.raises(StudyError, match="noise_scales"):
        small_methods_study(tmp_path, extra="[reactive]\nnoise_scales = [-1.0]")


def test_resume_refuses_another_studys_table(reference, tmp_path):
    _, _, tmp = reference
    f = study_file(tmp_path, trials=4, extra='[sweep]\nparameter = "v2_noise"\nvalues = [0.0, 0.0006]')
    f.write_text(f.read_text().replace("seed = 7", "seed = 2005"))
    with pytest.raises(StudyError, match=r"belongs to another study \(seed: 7 → 2005\)"):
        run_study(load_study(f), tmp / "a", resume=True, workers=1, progress=False)


def test_repeated_and_damaged_rows_do_not_corrupt_the_summary(reference, tmp_path, capsys):
    study, ref, tmp = reference
    out = tmp_path / "copy"
    out.mkdir()
    lines = (tmp / "a" / "trials.csv").read_text().splitlines()
    header, rows = lines[0], lines[1:]
    damaged = rows[1].split(",")
    damaged[header.split(",").index("success")] = "x"
    (out / "trials.csv").write_text("\n".join([header, *rows, rows[0], rows[0], ",".join(damaged)]) + "\n")
    (out / "study.json").write_text((tmp / "a" / "study.json").read_text())
    assert len(read_trials(out / "trials.csv")) == len(ref)  # the repeats count once
    (out / "trials.csv").write_text("\n".join([header, rows[0], rows[0], ",".join(damaged), *rows[2:]]) + "\n")
    summary = run_study(study, out, resume=True, workers=1, progress=False)  # row 1 (damaged) runs again
    err = capsys.readouterr().err
    assert "dropped 1 damaged row(s)" in err and "1 repeated trial(s)" in err
    assert [lv["trials"] for lv in summary["levels"]] == [4, 4]
    assert table(out) == ref


def test_one_output_folder_one_run(reference):
    from bench.montecarlo import _folder_lock

    study, _, tmp = reference
    with _folder_lock(tmp / "a"), pytest.raises(StudyError, match="is being written by rolltouch montecarlo pid"):
        run_study(study, tmp / "a", resume=True, workers=1, progress=False)


WORKERS = """
import multiprocessing, os, sys, time
from concurrent.futures import ProcessPoolExecutor
from bench.montecarlo import _die_with_parent

def hold():
    # a worker runs a task only once its initializer has returned: its pid written here is a worker
    # that watches its run already (one write, whole: the two workers share the pipe), after a second
    # in which a worker that took its living run for a dead one would have left
    time.sleep(1.0)
    os.write(1, f"{os.getpid()}\\n".encode())
    time.sleep(600)

if __name__ == "__main__":
    context = multiprocessing.get_context(sys.argv[1])
    pool = ProcessPoolExecutor(2, mp_context=context, initializer=_die_with_parent)
    futures = [pool.submit(hold) for _ in range(2)]
    for fut in futures:  # held while the tasks sleep; a task that could not run ends this script at once
        fut.result()
"""


def _state(pid):
    """A process's state letter (Z: a zombie, gone but not reaped)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return "Z"


@pytest.mark.parametrize("method", ["fork", "forkserver"])  # a forkserver worker's parent is the fork server
def test_workers_die_with_their_parent(tmp_path, method):
    (tmp_path / "workers.py").write_text(WORKERS)  # a file: spawned and fork-server workers import it
    parent = subprocess.Popen(
        [sys.executable, str(tmp_path / "workers.py"), method],
        stdout=subprocess.PIPE,
        text=True,
        cwd=ROOT,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    pids = [int(parent.stdout.readline()) for _ in range(2)]  # both tasks hold a worker each, at once
    assert len(set(pids)) == 2
    parent.send_signal(signal.SIGKILL)
    parent.wait()
    deadline = time.monotonic() + 10
    alive = pids
    while alive and time.monotonic() < deadline:
        time.sleep(0.05)
        alive = [p for p in pids if _state(p) != "Z"]
    assert not alive


def test_ctrl_c_keeps_the_finished_trials_and_does_not_wait_for_the_queue(tmp_path):
    """Interrupted after two trials of 1500 (the queue alone is minutes of work on two workers): it stops
    within 45 s however loaded the machine, keeping what finished."""
    f = study_file(tmp_path, trials=1500)
    out = tmp_path / "run"
    cmd = [*CLI, "montecarlo", str(f), "--out", str(out), "--workers", "2"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and len(read_trials(out / "trials.csv")) < 2:
        time.sleep(0.1)
    proc.send_signal(signal.SIGINT)
    t0 = time.monotonic()
    _, err = proc.communicate(timeout=60)
    waited = time.monotonic() - t0
    finished = read_trials(out / "trials.csv")
    assert proc.returncode == 130 and "finished trials are kept; rerun with --resume" in err
    assert waited < 45 and 2 <= len(finished) < 1500
    summary = json.loads((out / "summary.json").read_text())
    assert sum(lv["trials"] for lv in summary["levels"]) == len(finished)


def test_a_binary_study_or_part_is_one_clear_error(tmp_path):
    (tmp_path / "bin.toml").write_bytes(bytes(range(256)) * 8)
    with pytest.raises(StudyError, match="bin.toml: not a text file"):
        load_study(tmp_path / "bin.toml")
    (tmp_path / "bin.json").write_bytes(bytes(range(256)) * 8)
    f = tmp_path / "s.toml"
    f.write_text(f'parts = ["{tmp_path / "bin.json"}"]\nrolls_deg = [20.0]\n')
    with pytest.raises(StudyError, match="bin.json: not a text file"):
        load_study(f)


def test_an_absent_scheduler_is_named_quickly(reference, monkeypatch):
    pytest.importorskip("distributed")
    import bench.montecarlo

    study, _, tmp = reference
    monkeypatch.setattr(bench.montecarlo, "SCHEDULER_TIMEOUT", 1.0)
    t0 = time.monotonic()
    with pytest.raises(StudyError, match="no Dask scheduler answered within 1 s"):
        run_study(study, tmp / "nosched", scheduler="tcp://127.0.0.1:1", progress=False)
    assert time.monotonic() - t0 < 10


def test_a_world_study_writes_how_each_trials_world_differs_and_counts_mismatches(tmp_path):
    # issue 29: a [world] table adds the world's columns; the trials are the same as without it (the same
    # start and noise), and a run that met the defect says so in <m>_stopped, <m>_mismatch_arc and the
    # summary's mismatch count
    from bench.columns import WORLD_COLUMNS
    from bench.straight_trial import roll_straight
    from bench.trial_context import TrialSpec, draw_trial

    world = "[world]\ndefects = 1\ndefect_height_mm = 0.3\ndefect_length_mm = 4.0\n[reactive]\nmax_rotation_deg = 60.0"
    base = 'methods = ["reactive"]\n[reactive]\nmax_rotation_deg = 60.0'
    f = study_file(tmp_path, trials=2, extra=world.replace("[world]", 'methods = ["reactive"]\n[world]'))
    f.write_text(f.read_text().replace('method = "paper"\n', ""))
    study = load_study(f)
    assert study.world is not None and set(WORLD_COLUMNS) <= set(study.columns)
    assert "reactive_mismatch_arc" in study.columns
    run_study(study, tmp_path / "w", workers=1, progress=False)
    rows = table(tmp_path / "w")
    clean = tmp_path / "clean.toml"
    clean.write_text(f.read_text().split("[world]")[0].replace('methods = ["reactive"]\n', "") + base)
    # the same study without [world]: a trial's part and start are drawn, and its fixed rolls run, before any
    # method is scored (bench.trial.run_trial), so the reference stops there; its reactive rolling and plots
    # (most of a study's run) tell nothing of which trial it was
    clean_study = load_study(clean)
    assert clean_study.world is None
    clean_trials = [
        (ctx.head["part"], roll_straight(ctx))
        for ctx in (
            draw_trial(TrialSpec(clean_study, level, trial))
            for level in range(clean_study.levels)
            for trial in range(clean_study.trials)
        )
    ]
    assert len(rows) == len(clean_trials) == 2
    for r, (part, rolled) in zip(rows, clean_trials):
        assert rolled.failure == "" and float(r["start_arc"]) == rolled.start and r["part"] == part
        assert abs(float(r["world_defect_arc"]) - float(r["start_arc"])) <= 5.0
        assert float(r["world_defect_height_mm"]) == 0.3 and float(r["world_scale"]) == 1.0
        assert float(r["world_defect_length_mm"]) == 4.0
        assert r["reactive_stopped"] in ("confident", "mismatch", "budget", "ambiguous")
        assert bool(r["reactive_mismatch_arc"]) == (r["reactive_stopped"] == "mismatch")
        assert not (r["reactive_stopped"] == "confident" and r["reactive_success"] == "0")
    summary = json.loads((tmp_path / "w" / "summary.json").read_text())
    d = summary["method_details"]["reactive"]
    assert d["mismatch"] == sum(r["reactive_stopped"] == "mismatch" for r in rows)
    assert 0 <= d["mismatch_near"] <= d["mismatch"]


def test_resume_refuses_a_part_file_edited_since(tmp_path):
    part = tmp_path / "cam.json"
    doc = json.loads((ROOT / "parts" / "cam.json").read_text())
    part.write_text(json.dumps(doc))
    f = study_file(tmp_path, trials=2)
    f.write_text(f.read_text().replace(str(ROOT / "parts" / "cam.json"), str(part)))
    run_study(load_study(f), tmp_path / "out", workers=1, progress=False)
    saved = json.loads((tmp_path / "out" / "study.json").read_text())
    assert list(saved["fingerprints"]) == [str(part)]
    run_study(load_study(f), tmp_path / "out", resume=True, workers=1, progress=False)  # unchanged: resumes
    doc["points"][3][0] += 3.0  # one knot moved 3 mm
    part.write_text(json.dumps(doc))
    with pytest.raises(StudyError, match=r"cam\.json as it was before .* the part file has changed since"):
        run_study(load_study(f), tmp_path / "out", resume=True, workers=1, progress=False)


def test_the_command_lines_trials_are_bounded_as_the_study_files_are():
    from bench.study import MAX_TRIALS

    study = load_study(ROOT / "bench" / "studies" / "paper.toml")
    assert study.with_overrides(trials=7).trials == 7
    for bad, match in ((0, "at least 1"), (True, "at least 1"), (MAX_TRIALS + 1, "split the study")):
        with pytest.raises(StudyError, match=match):
            study.with_overrides(trials=bad)


def test_a_method_that_failed_every_trial_is_still_plotted_and_summed(tmp_path, paper_rule_refuses):
    study = small_methods_study(tmp_path)
    summary = run_study(study, tmp_path / "out", workers=1, progress=False)
    d = summary["method_details"]["paper"]
    assert d["success"] == 0 and d["failures"] == d["trials"] and d["mean_rotation_deg"] is None
    assert (tmp_path / "out" / "methods.png").stat().st_size > 5000
