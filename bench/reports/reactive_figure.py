"""The belief over the part as it sharpens during one reactive localization (a figure).

    python -m bench.reports.reactive_figure --out docs/generated/robustness/reactive [--part parts/trefoil.json]

Runs :func:`driver.jaw.reactive.localize_reactively` on a simulated rig with the ``paper``
noise and draws (1) the probability of the present contact along the part's
perimeter at several moments of the roll, and (2) the part with the belief at those
moments. Writes ``belief.png`` and prints where the run stopped.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeAlias

import numpy as np

from bench.reactive_method import reactive_filter, reactive_policy
from bench.study import load_study
from driver.jaw import calibrate_simulated, localize_reactively
from localizer import load_part, most_probable
from sim2d import SimRig, load_noise

if TYPE_CHECKING:
    from collections.abc import Sequence

    import numpy.typing as npt

    from driver.jaw import ReactiveRun
    from localizer import Outline, Part

    FloatArray: TypeAlias = npt.NDArray[np.float64]
    #: One belief check: (rotation rolled, rad; present contact of each hypothesis, mm; their posterior;
    #: the true contact, mm; the belief's mass within its radius of the estimate).
    Snapshot: TypeAlias = tuple[float, FloatArray, FloatArray, float, float]

ROOT = Path(__file__).resolve().parents[2]


def run(part_file: Path, start: float, seed: int) -> tuple[Part | Outline, ReactiveRun, list[Snapshot], float]:
    part = load_part(part_file)
    study = load_study(ROOT / "bench" / "studies" / "reactive.toml")
    noise = load_noise("paper")
    cal = calibrate_simulated(part, noise, seed=seed + 1)
    rig = SimRig(part, noise=noise, seed=seed)
    flt = reactive_filter(study, part, noise)
    snaps: list[Snapshot] = []

    def observe(event: dict[str, Any]) -> None:
        if event.get("event") == "belief":
            w = flt.posterior()
            snaps.append((event["rotation"], part.wrap_arc(flt.current.copy()), w, event["true_arc"], event["mass"]))

    res = localize_reactively(
        rig,
        part,
        calibration=cal,
        filter=flt,
        observer=observe,
        policy=reactive_policy(study),
        approach_pose=rig.approach_pose(start, jaw_position=-40.0, standoff=1.0),
    )
    return part, res, snaps, rig.truth()["contact_arc"]


def draw(part: Part | Outline, snaps: Sequence[Snapshot], out: Path, title: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pick = sorted({0, len(snaps) // 8, len(snaps) // 3, (2 * len(snaps)) // 3, len(snaps) - 1})
    fig = plt.figure(figsize=(13, 6.8))
    ax = fig.add_subplot(1, 2, 1)
    bins = np.linspace(0, part.perimeter, int(part.perimeter / 0.5) + 1)
    image = np.array([np.histogram(present, bins=bins, weights=w)[0] for _, present, w, _, _ in snaps])
    rot = np.degrees([sn[0] for sn in snaps])
    im = ax.imshow(
        np.log10(image + 1e-6),
        aspect="auto",
        origin="lower",
        cmap="magma",
        vmin=-6,
        vmax=0,
        extent=(0, part.perimeter, rot[0], rot[-1]),
        interpolation="nearest",
    )
    truth = np.array([sn[3] for sn in snaps])
    ax.plot(truth, rot, "c.", ms=2, label="true contact")
    ax.set_xlabel("present contact, arc position on the part (mm)")
    ax.set_ylabel("rotation rolled (degrees)")
    ax.legend(fontsize=8, loc="upper right")
    fig.colorbar(im, ax=ax, label="log10 probability per 0.5 mm")
    for i in pick:
        ax.axhline(rot[i], color="w", lw=0.5, ls=":")
    ax2 = fig.add_subplot(1, 2, 2)
    xy = part.sample(16)
    ax2.plot(xy[:, 0], xy[:, 1], color="0.6", lw=1)
    cmap = plt.get_cmap("viridis")
    for k, i in enumerate(pick):
        r, present, w, true_arc, mass = snaps[i]
        top = most_probable(w, 400)
        top = top[w[top] > 1e-3 * w.max()]
        p = part.point_at_arc(present[top])
        ax2.scatter(
            p[:, 0],
            p[:, 1],
            s=4 + 60 * w[top] / w[top].max(),
            color=cmap(k / max(1, len(pick) - 1)),
            alpha=0.5,
            label=f"{math.degrees(r):.0f}°: {mass:.0%} within 0.3 mm",
        )
        q = part.point_at_arc(true_arc)
        ax2.plot(q[0], q[1], "k+", ms=10)
    ax2.set_aspect("equal")
    ax2.legend(fontsize=8, title="rotation rolled", loc="upper right")
    ax2.set_title("where the belief is (hypotheses above 1/1000 of the best); +: the truth", fontsize=9)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(out / "belief.png", dpi=110)
    plt.close(fig)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m bench.reports.reactive_figure", description=__doc__.split("\n\n")[0]
    )
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--part", type=Path, default=ROOT / "parts" / "trefoil.json")
    parser.add_argument("--start", type=float, default=211.1, help="arc position of the first contact, mm")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    part, res, snaps, truth = run(args.part, args.start, args.seed)
    err = abs(float(part.arc_offset(res.estimate_arc, truth)))
    title = (
        f"{part.name}: reactive localization, paper noise — stopped ({res.stopped}) after "
        f"{math.degrees(res.rotation):.0f}°, error {err:.3f} mm"
    )
    draw(part, snaps, args.out, title)
    print(title)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
