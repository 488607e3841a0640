"""Which error source drives failures: the paper's setting with one noise source removed at a time.

Run ``python -m bench.reports.error_budget --out docs/generated/robustness/budget [--trials N]``. For each
group of noise-model fields it runs ``bench/studies/paper.toml`` with that group set to
zero (everything else at the ``paper`` levels) or, with ``--mode only``, with every other
group set to zero; plus the full preset and no noise at all. Writes ``summary.json`` and
``budget.png``.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from dataclasses import fields
from pathlib import Path
from typing import TYPE_CHECKING, Any

from bench.montecarlo import run_study
from bench.study import load_study
from bench.summary import wilson
from sim2d import PRESETS

if TYPE_CHECKING:
    from collections.abc import Sequence

GROUPS = {
    "twist noise (v2_noise)": ["v2_noise"],
    "bending noise (v1_noise)": ["v1_noise"],
    "ADC quantization": ["adc_step"],
    "drift": ["v1_drift", "v2_drift"],
    "encoder quantization": ["encoder_step"],
    "machining error": ["machining_error"],
    "offsets, gain, cross-talk, nonlinearity": ["v1_offset", "v2_offset", "gain_error", "crosstalk", "nonlinearity"],
}

#: The study the budget varies the noise of.
PAPER_STUDY = Path(__file__).resolve().parents[1] / "studies" / "paper.toml"


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="docs/generated/robustness/budget")
    ap.add_argument("--trials", type=int, default=150)
    ap.add_argument("--workers", type=int, default=None)
    ap.add_argument(
        "--mode",
        choices=("without", "only"),
        default="without",
        help="remove one group at a time, or keep only one group",
    )
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    base = load_study(PAPER_STUDY).with_overrides(trials=args.trials)
    paper = PRESETS["paper"]
    every = [n for names in GROUPS.values() for n in names]
    configs = {
        "paper (all sources)": {},
        "none": {f.name: 0.0 for f in fields(paper) if f.name != "machining_wavelength"},
    }
    if args.mode == "without":
        for label, names in GROUPS.items():
            configs[f"without {label}"] = {n: 0.0 for n in names}
    else:
        for label, names in GROUPS.items():
            configs[f"only {label}"] = {n: 0.0 for n in every if n not in names}
    results: dict[str, dict[str, Any]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for k, (label, zeroed) in enumerate(configs.items()):
            noise_file = Path(tmp) / f"noise{k}.toml"
            noise_file.write_text('preset = "paper"\n' + "".join(f"{n} = {v!r}\n" for n, v in zeroed.items()))
            study = load_study(PAPER_STUDY).with_overrides(trials=args.trials)
            from dataclasses import replace

            study = replace(study, noise=str(noise_file), name=label)
            print(f"{label} ...", file=sys.stderr, flush=True)
            s = run_study(study, out / f"config{k}", workers=args.workers, progress=False)
            lv = s["levels"][0]
            results[label] = {
                "zeroed": sorted(zeroed),
                "trials": lv["trials"],
                "success": lv["success"],
                "success_rate": lv["success_rate"],
                "ci95": list(wilson(lv["success"], lv["trials"])),
                "error_median_mm": lv["error_median_mm"],
            }
            print(
                f"  {lv['success']}/{lv['trials']} = {lv['success_rate']:.1%}, median error "
                f"{lv['error_median_mm']:.3f} mm",
                file=sys.stderr,
                flush=True,
            )
    (out / "summary.json").write_text(json.dumps(results, indent=2) + "\n")
    _plot(results, out / "budget.png", base.trials)
    print(json.dumps(results, indent=2))
    return 0


def _plot(results: dict[str, dict[str, Any]], path: Path, trials: int) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    labels = list(results)
    rate = np.array([results[k]["success_rate"] for k in labels])
    lo = np.array([results[k]["ci95"][0] for k in labels])
    hi = np.array([results[k]["ci95"][1] for k in labels])
    fig, ax = plt.subplots(figsize=(8, 4.8))
    y = np.arange(len(labels))
    ax.barh(y, rate, color=["tab:gray", "tab:green"] + ["tab:blue"] * (len(labels) - 2), alpha=0.75)
    ax.errorbar(rate, y, xerr=[rate - lo, hi - rate], fmt="none", color="k", capsize=3)
    ax.axvline(0.45, color="tab:red", ls="--", lw=1, label="the paper's rig: about 45%")
    ax.set_yticks(y, labels, fontsize=8)
    ax.invert_yaxis()
    ax.set_xlim(0, 1)
    ax.set_xlabel(f"success rate (final contact within 0.3 mm), {trials} trials each")
    ax.set_title("the paper's setting with one error source removed, or alone", fontsize=10)
    ax.legend(fontsize=8, loc="lower right")
    ax.grid(alpha=0.3, axis="x")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())
