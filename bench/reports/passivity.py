"""The seed's passivity study, reproduced, and the guarded contact-force servo.

    python -m bench.reports.passivity --json              # the four variants' noise and min_energy
    python -m bench.reports.passivity --out docs/generated/passivity # plus the servo comparison, plots, summary.json

Part 1 (Ryu et al. 2005): the one-axis device of :mod:`sim2d.haptic`, an
operator pressing slowly into a 20 kN/m virtual wall and out again, with a
passivity observer/controller on the wall's port ("observed" booking: the held
output against the next differenced velocity). Variants: ``plain``,
``sign_fix``, ``hold_fix``, ``both``. Noise metric: the total variation of the
controller's force per second (N/s) over the run; also per phase.
``min_energy`` is the lowest observed energy after the controller (J).

Part 2: the arm's contact-force servo (:class:`sim2d.haptic.Servo`) at rising
gains, bare and guarded (both fixes), with the ``paper`` preset's sensor noise
and resolution: contact losses and force ripple in the second half of a 1 s hold.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from passivity import PassivityController
from sim2d.haptic import Axis, Operator, Servo, simulate_servo, simulate_wall
from sim2d.noise import PRESETS
from sim2d.wrist import Wrist

if TYPE_CHECKING:
    from collections.abc import Sequence

    from sim2d.haptic import AxisTrace

VARIANTS = {
    "plain": {},
    "sign_fix": {"sign_fix": True},
    "hold_fix": {"hold_fix": True},
    "both": {"sign_fix": True, "hold_fix": True},
}
GAINS = (2.0, 5.0, 10.0, 20.0, 40.0)


def controller(variant: str, dt: float, booking: str = "observed") -> PassivityController:
    """The passivity controller of one variant."""
    return PassivityController(dt, booking=booking, **VARIANTS[variant])


def wall_study(
    axis: Axis = Axis(), operator: Operator = Operator()
) -> tuple[dict[str, dict[str, Any]], dict[str, Any]]:
    """Run the four variants (and the bare wall). Returns (results, traces)."""
    results, traces = {}, {}
    for name in VARIANTS:
        tr = simulate_wall(controller(name, axis.dt), axis=axis, operator=operator)
        traces[name] = tr
        results[name] = {
            "noise": tr.noise(),
            "min_energy": float(tr.energy.min()),
            "final_energy": float(tr.energy[-1]),
            "noise_by_phase": {p: tr.noise(t0, t1) for p, t0, t1 in tr.phases},
            "max_control": float(np.abs(tr.control).max()),
            "max_penetration_mm": float(tr.position.max() * 1e3),
        }
    bare = simulate_wall(None, axis=axis, operator=operator)
    traces["bare"] = bare
    assumed = simulate_wall(controller("plain", axis.dt, booking="assumed"), axis=axis, operator=operator)
    extra = {
        "bare_wall": {
            "max_penetration_mm": float(bare.position.max() * 1e3),
            "wall_force_variation": float(np.abs(np.diff(bare.port_force)).sum() / bare.time[-1]),
        },
        "plain_assumed_booking": {"noise": assumed.noise(), "min_energy": float(assumed.energy.min())},
    }
    return results, {"traces": traces, "extra": extra}


def servo_study(
    gains: Sequence[float] = GAINS, noise: str = "paper", duration: float = 1.0, seed: int = 0
) -> tuple[list[dict[str, Any]], dict[str, AxisTrace]]:
    """The contact servo, bare and guarded, at each gain. Returns (rows, traces at gain 20)."""
    model = PRESETS[noise]
    volts_per_newton = Wrist().volts_per_newton
    sensor_noise = model.v1_noise / volts_per_newton
    sensor_resolution = model.adc_step / volts_per_newton
    axis = Axis(damping=5.0)
    rows, traces = [], {}
    for gain in gains:
        servo = Servo(gain=gain, sensor_noise=sensor_noise, sensor_resolution=sensor_resolution, duration=duration)
        for guard in (False, True):
            pc = controller("both", axis.dt) if guard else None
            tr = simulate_servo(servo, pc, axis=axis, seed=seed)
            tail = tr.time >= duration / 2
            cf = tr.contact_force[tail]
            rows.append(
                {
                    "gain": gain,
                    "guarded": guard,
                    "contact_lost_samples": int((cf == 0).sum()),
                    "force_mean": float(cf.mean()),
                    "force_std": float(cf.std()),
                    "force_variation": float(np.abs(np.diff(cf)).sum() / (duration / 2)),
                    "max_force": float(tr.contact_force.max()),
                    "min_energy": float(tr.energy.min()),
                }
            )
            if gain == 20.0:
                traces["guarded" if guard else "bare"] = tr
    return rows, traces


def _plots(out: Path, wall: dict[str, Any], servo_traces: dict[str, AxisTrace]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    traces = wall["traces"]
    fig, axes = plt.subplots(4, 1, figsize=(10, 11), sharex=True)
    bare = traces["bare"]
    axes[0].plot(bare.time, bare.position * 1e3, color="0.6", lw=0.8, label="bare wall")
    for name in VARIANTS:
        tr = traces[name]
        axes[0].plot(tr.time, tr.position * 1e3, lw=0.8, label=name)
        axes[1].plot(tr.time, tr.control, lw=0.6, label=f"{name}: {tr.noise():.0f} N/s")
        axes[2].plot(tr.time, tr.energy, lw=0.8, label=name)
    axes[3].plot(bare.time, bare.velocity * 1e3, lw=0.5, color="0.4")
    axes[0].set_ylabel("position (mm)")
    axes[0].set_ylim(-0.6, 0.7)
    axes[1].set_ylabel("PC force (N)")
    axes[1].set_ylim(-12, 12)
    axes[2].set_ylabel("observed energy (J)")
    axes[2].set_ylim(-2e-3, 1e-3)
    axes[3].set_ylabel("differenced v,\nbare wall (mm/s)")
    axes[3].set_xlabel("time (s)")
    for ax in axes[:3]:
        ax.legend(fontsize=7, loc="upper right")
    for ax in axes:
        for _name, t0, _t1 in bare.phases[1:]:
            ax.axvline(t0, color="k", lw=0.5, ls=":")
    fig.suptitle("1-DOF device on a 20 kN/m wall: passivity controller variants")
    fig.tight_layout()
    fig.savefig(out / "wall.png", dpi=110)
    plt.close(fig)

    fig, axes = plt.subplots(2, 1, figsize=(10, 6), sharex=True)
    for name, tr in servo_traces.items():
        axes[0].plot(tr.time, tr.contact_force, lw=0.7, label=name)
        axes[1].plot(tr.time, tr.position * 1e3, lw=0.7, label=name)
    axes[0].set_ylabel("contact force (N)")
    axes[1].set_ylabel("jaw position (mm)\n(part surface at 0)")
    axes[1].set_xlabel("time (s)")
    axes[0].legend()
    fig.suptitle("contact-force servo at gain 20: bare loop vs passivity-guarded")
    fig.tight_layout()
    fig.savefig(out / "servo.png", dpi=110)
    plt.close(fig)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench.reports.passivity", description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--json",
        action="store_true",
        help="print {variant: {noise, min_energy, ...}} for plain, sign_fix, hold_fix, both",
    )
    parser.add_argument("--out", type=Path, help="also run the servo study; write summary.json and plots here")
    args = parser.parse_args(argv)
    results, wall = wall_study()
    if args.json:
        print(json.dumps(results, indent=2))
    else:
        print(f"{'variant':10s} {'noise N/s':>10s} {'min_energy J':>13s} {'max |PC| N':>10s}")
        for name, r in results.items():
            print(f"{name:10s} {r['noise']:10.1f} {r['min_energy']:13.2e} {r['max_control']:10.2f}")
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
        rows, servo_traces = servo_study()
        summary = {
            "wall": results,
            **wall["extra"],
            "servo": rows,
            "metric": "noise = total variation of the passivity controller's force per second (N/s)",
        }
        (args.out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
        _plots(args.out, wall, servo_traces)
        if not args.json:
            print(f"\n{'gain':>5s} {'guard':>6s} {'lost':>5s} {'std N':>7s} {'var N/s':>8s}")
            for r in rows:
                print(
                    f"{r['gain']:5.0f} {str(r['guarded']):>6s} {r['contact_lost_samples']:5d} "
                    f"{r['force_std']:7.3f} {r['force_variation']:8.1f}"
                )
            print(f"wrote {args.out}/summary.json, wall.png, servo.png", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
