"""The Cramér–Rao bound of one roll, against the spread of the exact solver's answers to noisy rolls."""

from pathlib import Path

import numpy as np
import pytest

from localizer import QueryError, TrialNoise, feasible_segments, load_part, roll_bound, trial_bound

PARTS = Path(__file__).resolve().parents[2] / "parts"


@pytest.mark.parametrize("start, length", [(115.0, 12.0), (85.0, 8.0)])
def test_the_solvers_answers_to_noisy_rolls_spread_as_the_bound_says(start, length):
    # small noise: the solution of two readings in two unknowns is efficient, so its spread over
    # 600 noisy rolls is the bound (sampling error of a standard deviation ~3%; 12% allowed)
    cam = load_part(PARTS / "cam.json")
    sd_l, sd_o = 0.01, 2e-4
    raw = float(cam.tangent_angle_at_arc(start + length) - cam.tangent_angle_at_arc(start))
    turn = (raw + np.pi) % (2 * np.pi) - np.pi  # a short roll turns by less than half a turn
    rng = np.random.default_rng(7)
    starts, ends = [], []
    for _ in range(600):
        segs = feasible_segments(cam, length + rng.normal(0, sd_l), turn + rng.normal(0, sd_o))
        near = min(segs, key=lambda g: abs(cam.arc_offset(g.start_arc, start)))
        starts.append(float(cam.arc_offset(near.start_arc, start)))
        ends.append(float(cam.arc_offset(near.end_arc, start + length)))
    for got, at in ((starts, "start"), (ends, "end")):
        bound = float(roll_bound(cam, start, length, sd_length=sd_l, sd_turn=sd_o, at=at))
        assert np.isfinite(bound) and np.std(got) == pytest.approx(bound, rel=0.12), (at, np.std(got), bound)


def test_bad_queries_are_refused_by_name():
    cam = load_part(PARTS / "cam.json")
    for kwargs, says in (
        ({"length": -1.0, "sd_length": 0.1, "sd_turn": 0.1}, "length"),
        ({"length": 5.0, "sd_length": float("nan"), "sd_turn": 0.1}, "sd_length"),
        ({"length": 5.0, "sd_length": 0.1, "sd_turn": 0.1, "at": "middle"}, "middle"),
    ):
        with pytest.raises(QueryError, match=says):
            roll_bound(cam, 10.0, **kwargs)


def _egg():
    from localizer import part_from_points

    a = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    return part_from_points(np.c_[30 * np.cos(a) + 4 * np.cos(2 * a), 22 * np.sin(a)])


def _dense_fisher_bound(part, path, segments, sd_z, sd_o, sd_b, rms=0.0, wavelength=20.0):
    """Reference: the whole Fisher matrix over (σ_0 … σ_k, φ, c_1 … c_S, b, deviation coefficients), θ'
    by central differences, the deviation's travel term by dense quadrature, inverted densely (no
    elimination)."""
    k = len(path)
    P = part.perimeter
    labels = sorted(set(segments))
    harm = np.arange(1, int(P / wavelength) + 1) if rms > 0 else np.arange(0)
    n_d = 2 * harm.size
    n = k + 1 + len(labels) + 1 + n_d
    rows, w = [], []
    h = 1e-5

    def dev_columns(s):  # d'(s) per coefficient, and ∫_{path[0]}^{s} κ·basis dσ
        om = 2 * np.pi * harm / P
        slope = np.r_[-om * np.sin(om * s), om * np.cos(om * s)]
        x = np.linspace(path[0], s, 2001)
        kap = np.asarray(part.curvature_at_arc(np.mod(x, P)), float)[:, None]
        basis = np.hstack([np.cos(np.outer(x, om)), np.sin(np.outer(x, om))])
        return slope, np.trapezoid(kap * basis, x, axis=0) if n_d else np.zeros(0)

    for j, (s, g) in enumerate(zip(path, segments)):
        slope, grow = dev_columns(s)
        rz = np.zeros(n)
        rz[j] = 1.0
        rz[k + 1 + labels.index(g)] = 1.0
        rz[k + 1 + len(labels)] = s - path[0]
        rz[n - n_d :] = grow
        ro = np.zeros(n)
        ro[j] = float(part.tangent_angle_at_arc(s + h) - part.tangent_angle_at_arc(s - h)) / (2 * h)
        ro[k] = 1.0
        ro[n - n_d :] = slope
        rows += [rz, ro]
        w += [1 / sd_z**2, 1 / sd_o**2]
    H = np.array(rows)
    J = H.T @ (np.array(w)[:, None] * H)
    J[k + 1 + len(labels), k + 1 + len(labels)] += 1 / sd_b**2
    if n_d:
        var = rms**2 / (harm**2 * np.sum(1.0 / harm**2))
        J[n - n_d :, n - n_d :] += np.diag(np.tile(1 / var, 2))
    return float(np.sqrt(np.linalg.inv(J)[k - 1, k - 1]))


@pytest.mark.parametrize("segments, rms", [([0] * 12, 0.0), ([0] * 5 + [1] * 7, 0.0), ([0] * 5 + [1] * 7, 0.009)])
def test_trial_bound_is_the_dense_fisher_bound(segments, rms):
    egg = _egg()
    path = list(np.r_[np.linspace(10.0, 25.0, 8), np.linspace(24.0, 18.0, 4)])  # out and partly back
    noise = TrialNoise(sd_position=0.02, sd_turn=3e-4, sd_scale=0.02, machining_error=rms)
    got = trial_bound(egg, path, noise, segments=segments)
    ref = _dense_fisher_bound(egg, path, segments, 0.02, 3e-4, 0.02, rms)
    assert got == pytest.approx(ref, rel=1e-4)


def test_trial_bound_spread_of_the_maximum_likelihood_place():
    """Small noise: the maximum-likelihood estimate of the whole model is efficient, so the spread of its
    final place over 300 simulated trials is the bound (sampling error ~4%; 15% allowed)."""
    from scipy.optimize import least_squares

    egg = _egg()
    path = np.linspace(12.0, 30.0, 7)
    sd_z, sd_o, sd_b = 0.01, 2e-4, 0.01
    theta = np.asarray(egg.tangent_angle_at_arc(path), float)
    rng = np.random.default_rng(11)
    finals = []
    for _ in range(300):
        b = 1 + rng.normal(0, sd_b)
        z = 3.0 + b * (path - path[0]) + rng.normal(0, sd_z, path.size)
        om = theta + 0.5 + rng.normal(0, sd_o, path.size)

        def residuals(x, z=z, om=om):
            sig, phi, c, bb = x[: path.size], x[-3], x[-2], x[-1]
            th = np.asarray(egg.tangent_angle_at_arc(sig), float)
            return np.r_[(z - c - bb * (sig - sig[0])) / sd_z, (om - th - phi) / sd_o, [(bb - 1) / sd_b]]

        def jacobian(x):
            # the residuals' derivatives in closed form (dθ/dσ = κ), not by differences: a tenth of the calls
            n, sig, bb = path.size, x[: path.size], x[-1]
            jac = np.zeros((2 * n + 1, n + 3))
            jac[1:n, 1:n] = -bb / sd_z * np.eye(n - 1)
            jac[1:n, 0] = bb / sd_z
            jac[:n, n + 1] = -1 / sd_z
            jac[:n, n + 2] = -(sig - sig[0]) / sd_z
            jac[n : 2 * n, :n] = -np.diag(np.asarray(egg.curvature_at_arc(sig), float)) / sd_o
            jac[n : 2 * n, n] = -1 / sd_o
            jac[2 * n, n + 2] = 1 / sd_b
            return jac

        x0 = np.r_[path, 0.5, 3.0, 1.0]
        finals.append(least_squares(residuals, x0, jac=jacobian, x_scale="jac").x[path.size - 1] - path[-1])
    bound = trial_bound(egg, path, TrialNoise(sd_position=sd_z, sd_turn=sd_o, sd_scale=sd_b))
    assert np.std(finals) == pytest.approx(bound, rel=0.15), (np.std(finals), bound)


def test_trial_bound_falls_with_readings_rises_with_nuisances_and_is_infinite_on_a_circle():
    from localizer import part_from_points

    egg = _egg()
    path = np.linspace(10.0, 40.0, 61)
    base = TrialNoise(sd_position=0.02, sd_turn=3e-4)
    short, longer = trial_bound(egg, path[:20], base), trial_bound(egg, path, base)
    assert longer < short
    scaled = trial_bound(egg, path, TrialNoise(0.02, 3e-4, sd_scale=0.05))
    assert scaled > longer
    assert trial_bound(egg, path, TrialNoise(0.02, 3e-4, sd_scale=0.05, machining_error=0.01)) > scaled
    a = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    circle = part_from_points(np.c_[30 * np.cos(a), 30 * np.sin(a)])
    assert trial_bound(circle, path, base) > 100 * longer  # a spline circle's curvature varies by 1e-5
    with pytest.raises(QueryError, match="sd_turn"):
        TrialNoise(sd_position=0.02, sd_turn=0.0)
    with pytest.raises(QueryError, match="segments"):
        trial_bound(egg, path, base, segments=[0, 1])
