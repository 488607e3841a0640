"""Studies of the simulated rig: rolling fidelity (paper §III-C), calibration, engines, end to end.

Run ``python -m bench.reports.sim_study [--out docs/generated/sim] [--trials N]``: prints the
figures, writes ``summary.json`` and PNG plots into ``--out``; ``docs/simulation.md``
quotes them.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeAlias

import numpy as np

from bench.benchmarks.baselines import PARTS_DIR
from driver.jaw import (
    calibrate_simulated,
    delta_voltages,
    establish_contact,
    laid_off,
    localize_by_rolling,
    roll,
)
from driver.rig import RigError
from localizer import SUCCESS_RADIUS, Part, load_part
from sim2d import SimRig

if TYPE_CHECKING:
    from collections.abc import Sequence

    import numpy.typing as npt

    FloatArray: TypeAlias = npt.NDArray[np.float64]

SHIPPED = ("cam.json", "ellipse.json", "trefoil.json", "kidney.csv")


def _log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def fidelity(
    steps_deg: Sequence[float] = (0.8, 0.4, 0.2, 0.1),
    starts: Sequence[float] = (20.0, 90.0, 160.0, 230.0),
    angle_deg: float = 40.0,
) -> list[dict[str, Any]]:
    """Noise-free rolls on the cam: the paper's L estimate and ours against the true arc length."""
    part = load_part(PARTS_DIR / "cam.json")
    cal = calibrate_simulated(part)
    rows: list[dict[str, Any]] = []
    for deg in steps_deg:
        for start in starts:
            rig = SimRig(part, noise="none", seed=1)
            hand, base, _ = establish_contact(rig, rig.approach_pose(start, jaw_position=-40, standoff=1.0))
            a0 = rig.truth()["contact_arc"]
            r = roll(rig, hand, base, cal, math.radians(angle_deg), step=math.radians(deg))
            true_len = (rig.truth()["contact_arc"] - a0) % part.perimeter
            true_turn = float(part.tangent_angle_at_arc(a0 + true_len) - part.tangent_angle_at_arc(a0))
            rows.append(
                {
                    "step_deg": deg,
                    "start": start,
                    "true_length": true_len,
                    "paper_error": r.jaw_travel - true_len,
                    "paper_offset_error": r.jaw_travel + r.offset * abs(r.turn) - true_len,
                    "ours_error": r.length - true_len,
                    "turn_error": r.turn - true_turn,
                    "offset": r.offset,
                }
            )
        _log(f"  fidelity: step {deg}°")
    return rows


def calibration_accuracy(
    noises: Sequence[str] = ("none", "paper"), seeds: Sequence[int] = (0, 1, 2)
) -> dict[str, dict[str, float]]:
    part = load_part(PARTS_DIR / "cam.json")
    out: dict[str, dict[str, float]] = {}
    for noise in noises:
        errs: list[float] | FloatArray  # the name serves twice: the readings' errors, then as an array
        errs = []
        for seed in seeds:
            cal = calibrate_simulated(part, noise, seed=seed)
            rig = SimRig(part, noise=noise, seed=seed + 10)
            for d in np.linspace(-45, 45, 19):
                _, base, _ = establish_contact(rig, rig.approach_pose(120.0, jaw_position=d, standoff=1.0))
                dv1, dv2 = delta_voltages(rig, base, 32)
                errs.append(cal.position(dv2 / dv1) - rig.truth()["jaw_position"])
        errs = np.array(errs)
        out[noise] = {
            "readings": int(errs.size),
            "rms_mm": float(np.sqrt(np.mean(errs**2))),
            "max_mm": float(np.abs(errs).max()),
        }
    return out


def engines(starts: Sequence[float] = (20.0, 120.0, 200.0)) -> list[dict[str, Any]]:
    """The same noise-free two-roll runs on the kinematic and the pymunk rig."""
    part = load_part(PARTS_DIR / "cam.json")
    cal = calibrate_simulated(part)
    rows: list[dict[str, Any]] = []
    for start in starts:
        res: dict[str, dict[str, Any]] = {}
        for engine in ("kinematic", "pymunk"):
            rig = SimRig(part, noise="none", seed=1, engine=engine)
            t0 = time.perf_counter()
            run = localize_by_rolling(
                rig,
                part,
                [math.radians(30), math.radians(25)],
                calibration=cal,
                approach_pose=rig.approach_pose(start, jaw_position=-40, standoff=1.0),
            )
            truth = rig.truth()["contact_arc"]
            res[engine] = {
                "estimates": [list(e) for e in run.estimates],
                "seconds": time.perf_counter() - t0,
                "error_mm": abs(float(part.arc_offset(run.estimate_arc, truth))),
                "true_arc": truth,
            }
        d = np.abs(np.array(res["kinematic"]["estimates"]) - np.array(res["pymunk"]["estimates"]))
        rows.append(
            {
                "start": start,
                **res,
                "length_diff_max_mm": float(d[:, 0].max()),
                "turn_diff_max_rad": float(d[:, 1].max()),
            }
        )
        _log(f"  engines: start {start}")
    return rows


#: The standard deviations the localizer is told, matched to each noise level: with "none"
#: the estimates are exact to ~1e-4 mm (fidelity study); with "paper" the L estimates
#: are off by ~0.2 mm and the encoder quantizes to 0.03°.
LIKELIHOOD_SD = {"none": (0.01, 1e-5), "paper": (0.3, math.radians(0.03))}


def end_to_end(
    noise: str, trials: int, seed: int, engine: str = "kinematic", rolls_deg: Sequence[float] = (20.0, 15.0)
) -> dict[str, dict[str, Any]]:
    """Two rolls from random starts on every shipped part: success (< 0.3 mm), refusals, ambiguity."""
    rng = np.random.default_rng(seed)
    sd_length, sd_turn = LIKELIHOOD_SD[noise]
    out: dict[str, dict[str, Any]] = {}
    for name in SHIPPED:
        part = load_part(PARTS_DIR / name)
        if not isinstance(part, Part):
            raise TypeError(f"{name}: the paper's study rolls on the shipped point-file parts")
        cal = calibrate_simulated(part, noise, seed=seed, engine=engine)
        rows: list[dict[str, Any]] = []
        for _k in range(trials):
            start = float(rng.uniform(0, part.perimeter))
            rig = SimRig(part, noise=noise, seed=int(rng.integers(1 << 31)), engine=engine)
            try:
                run = localize_by_rolling(
                    rig,
                    part,
                    [math.radians(a) for a in rolls_deg],
                    calibration=cal,
                    approach_pose=rig.approach_pose(start, jaw_position=-40, standoff=1.0),
                    sd_length=sd_length,
                    sd_turn=sd_turn,
                )
            except RigError as exc:
                rows.append({"start": start, "refused": str(exc)[:120]})
                continue
            first = run.rolls[0].truth[0].contact_arc
            if laid_off(part, first, start):  # the start is not on the hull
                rows.append({"start": start, "refused": f"not on the convex hull (touched at {first:.2f} mm)"})
                continue
            truth = rig.truth()["contact_arc"]
            best = run.localization.best
            if best is None:  # no place on the part fits the noisy measurements
                rows.append(
                    {
                        "start": start,
                        "error_mm": math.inf,
                        "ambiguous": True,
                        "top2_error_mm": math.inf,
                        "no_candidate": True,
                    }
                )
                continue
            top2 = run.localization.candidates[:2]
            rows.append(
                {
                    "start": start,
                    "error_mm": abs(float(part.arc_offset(best.end_arc, truth))),
                    "ambiguous": run.localization.ambiguous,
                    "top2_error_mm": min(abs(float(part.arc_offset(c.end_arc, truth))) for c in top2),
                }
            )
        done = [r for r in rows if "error_mm" in r]
        ok = sum(r["error_mm"] < SUCCESS_RADIUS for r in done)
        n = len(done)
        # Wilson 95% interval of the success rate
        z = 1.96
        p = ok / n if n else float("nan")
        half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n) if n else float("nan")
        centre = (p + z * z / (2 * n)) / (1 + z * z / n) if n else float("nan")
        out[name] = {
            "trials": trials,
            "localized": n,
            "refused": trials - n,
            "success": ok,
            "success_rate": p,
            "ci95": [centre - half, centre + half],
            "ambiguous": sum(r["ambiguous"] for r in done),
            "success_top2": sum(r["top2_error_mm"] < SUCCESS_RADIUS for r in done),
            "no_candidate": sum(bool(r.get("no_candidate")) for r in done),
            "median_error_mm": float(np.median([r["error_mm"] for r in done])) if done else None,
            "rows": rows,
        }
        _log(f"  end to end ({noise}): {name}: {ok}/{n} within {SUCCESS_RADIUS} mm, {trials - n} refused")
    return out


def _plot(out: Path, fid: list[dict[str, Any]], e2e_paper: dict[str, dict[str, Any]]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.3))
    steps = sorted({r["step_deg"] for r in fid})
    for key, label, mark in (
        ("paper_offset_error", "paper: Δu summed (+ edge offset)", "o"),
        ("ours_error", "ours: second-order inversion", "s"),
    ):
        v = [np.mean([abs(r[key]) for r in fid if r["step_deg"] == s]) for s in steps]
        a1.loglog(steps, v, mark + "-", label=label)
    a1.loglog(
        steps,
        [np.mean([abs(r["paper_error"]) for r in fid if r["step_deg"] == s]) for s in steps],
        "^-",
        label="Δu summed, no edge offset",
    )
    a1.set_xlabel("rolling step θ (degrees)")
    a1.set_ylabel("|L estimate - true arc length| (mm), 40° roll")
    a1.set_title("rolling fidelity, noise none (cam)")
    a1.legend(fontsize=8)
    a1.grid(alpha=0.3, which="both")
    names = list(e2e_paper)
    rates = [e2e_paper[n]["success_rate"] for n in names]
    lo = [e2e_paper[n]["ci95"][0] for n in names]
    hi = [e2e_paper[n]["ci95"][1] for n in names]
    x = np.arange(len(names))
    a2.bar(x, rates, color="tab:blue", alpha=0.7)
    a2.errorbar(x, rates, yerr=[np.array(rates) - lo, np.array(hi) - rates], fmt="none", color="k", capsize=4)
    a2.axhline(0.45, color="tab:red", lw=1, ls="--", label="the paper's rig: about 45%")
    a2.set_xticks(x, [n.split(".")[0] for n in names])
    a2.set_ylim(0, 1)
    a2.set_ylabel("success rate (final contact within 0.3 mm)")
    a2.set_title("two rolls (20°, 15°), paper noise, random starts")
    a2.legend(fontsize=8)
    a2.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    fig.savefig(out / "simulation.png", dpi=110)
    plt.close(fig)


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="docs/generated/sim")
    ap.add_argument("--trials", type=int, default=40, help="random starts per part and noise level")
    ap.add_argument("--seed", type=int, default=2005)
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    _log("fidelity ...")
    fid = fidelity()
    _log("calibration ...")
    calib = calibration_accuracy()
    _log("engines ...")
    eng = engines()
    _log("end to end, noise none ...")
    none = end_to_end("none", args.trials, args.seed)
    _log("end to end, noise paper ...")
    paper = end_to_end("paper", args.trials, args.seed + 1)
    table = {}
    for s in sorted({r["step_deg"] for r in fid}, reverse=True):
        sel = [r for r in fid if r["step_deg"] == s]
        table[str(s)] = {
            k: float(np.mean([abs(r[k]) for r in sel]))
            for k in ("paper_error", "paper_offset_error", "ours_error", "turn_error")
        }
    summary = {
        "fidelity_mean_abs_error_mm": table,
        "calibration": calib,
        "engines": [{k: v for k, v in r.items()} for r in eng],
        "end_to_end_none": {k: {kk: vv for kk, vv in v.items() if kk != "rows"} for k, v in none.items()},
        "end_to_end_paper": {k: {kk: vv for kk, vv in v.items() if kk != "rows"} for k, v in paper.items()},
    }
    (out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    (out / "end_to_end_rows.json").write_text(
        json.dumps(
            {"none": {k: v["rows"] for k, v in none.items()}, "paper": {k: v["rows"] for k, v in paper.items()}},
            indent=1,
        )
        + "\n"
    )
    _plot(out, fid, paper)
    print(json.dumps(summary, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
