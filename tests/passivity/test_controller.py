"""The passivity observer/controller on hand-computed sequences."""

import math

import pytest

from passivity import ControlError, PassivityController

DT = 0.001


def test_observer_sums_port_energy_when_passive():
    pc = PassivityController(DT)
    e = 0.0
    for f, v in [(1.0, 0.01), (2.0, 0.02), (0.5, -0.01)]:
        step = pc.update(f, v)
        e += DT * f * v
        assert step.energy == pytest.approx(e) and step.control == 0.0
    assert e == pytest.approx(DT * (0.01 + 0.04 - 0.005))


def test_controller_dissipates_exactly_the_produced_energy():
    pc = PassivityController(DT)
    pc.update(1.0, 0.01)  # E = 1e-5
    step = pc.update(-3.0, 0.01)  # produces 3e-5: E = -2e-5
    alpha = 2e-5 / (DT * 0.01**2)  # 200 N·s/m
    assert step.alpha == pytest.approx(alpha)
    assert step.control == pytest.approx(alpha * 0.01)
    assert step.force == pytest.approx(-3.0 + 2.0)
    assert step.energy == pytest.approx(0.0, abs=1e-18)
    nxt = pc.update(0.0, 0.005)  # the dissipation is booked into the observer
    assert pc.energy == pytest.approx(0.0, abs=1e-18) and nxt.alpha == 0.0


def test_no_division_by_zero_at_zero_velocity():
    pc = PassivityController(DT)
    pc.update(-5.0, 0.01)  # E < 0, damped
    step = pc.update(-5.0, 0.0)
    assert step.alpha == 0.0 and step.control == 0.0 and math.isfinite(step.force)


def test_hold_fix_holds_the_control_force_while_v_is_zero_and_nothing_else():
    plain, hold = PassivityController(DT), PassivityController(DT, hold_fix=True)
    seq = [(-5.0, 0.01), (-5.0, 0.0), (-5.0, 0.0), (1.0, 0.01)]
    a = [plain.update(f, v) for f, v in seq]
    b = [hold.update(f, v) for f, v in seq]
    assert b[0] == a[0]
    assert a[1].control == 0.0 and b[1].control == pytest.approx(a[0].control)
    assert b[2].control == pytest.approx(a[0].control)
    assert b[1].energy == a[1].energy and b[2].energy == a[2].energy  # a held force at v = 0 does no work
    assert b[3] == a[3]


def test_sign_fix_ignores_only_energy_produced_at_a_velocity_sign_change():
    plain, fixed = PassivityController(DT), PassivityController(DT, sign_fix=True)
    seq = [(2.0, 0.01), (2.0, -0.01), (-2.0, -0.01), (-2.0, 0.01)]
    a = [plain.update(f, v).energy for f, v in seq]
    b = [fixed.update(f, v).energy for f, v in seq]
    assert a[0] == b[0]
    # sample 1: sign change with produced energy (2 N × -0.01 m/s): ignored by the fix
    assert a[1] == pytest.approx(0.0) and b[1] == pytest.approx(2e-5)
    # sample 2: no sign change, absorbed energy: counted by both
    assert b[2] - b[1] == pytest.approx(DT * 2.0 * 0.01)
    # sample 3: sign change, produced energy: ignored again
    assert b[3] == pytest.approx(b[2])
    # absorbed energy at a sign change is always counted
    c = PassivityController(DT, sign_fix=True)
    c.update(-1.0, -0.01)
    assert c.update(1.0, 0.01).energy == pytest.approx(2 * DT * 0.01)


def test_force_limit_bounds_the_control_and_keeps_the_rest_in_the_observer():
    pc = PassivityController(DT, force_limit=0.5)
    step = pc.update(-3.0, 0.01)  # would need 3 N of control
    assert step.control == pytest.approx(0.5)
    assert step.energy == pytest.approx(-3e-5 + DT * 0.5 * 0.01)


def test_bad_parameters():
    with pytest.raises(ControlError, match="dt=0"):
        PassivityController(0)
    with pytest.raises(ControlError, match="force_limit=-1"):
        PassivityController(DT, force_limit=-1)


def test_observed_booking_pairs_the_held_output_with_the_next_motion():
    pc = PassivityController(DT, booking="observed")
    s0 = pc.update(2.0, 0.01)  # nothing was held before: books 0
    assert s0.energy == 0.0 and s0.control == 0.0
    s1 = pc.update(5.0, 0.02)  # 2 N held while moving 0.02 m/s
    assert pc.energy == pytest.approx(DT * 2.0 * 0.02)
    s2 = pc.update(0.0, -0.01)  # 5 N held, moving back: produces 5e-5 J
    e = DT * (2.0 * 0.02 - 5.0 * 0.01)
    assert pc.energy == pytest.approx(e) and e < 0
    assert s2.control == pytest.approx(-e / (DT * -0.01))  # α·v with α = -E/(ΔT v²)
    assert s2.energy == pytest.approx(0.0, abs=1e-18)
    # the control force is part of the held output: its work is observed, not assumed
    pc.update(0.0, -0.01)
    assert pc.energy == pytest.approx(e + DT * s2.control * -0.01)
    assert s1.control == 0.0


def test_a_sampled_spring_is_passive_when_assumed_and_active_when_observed():
    k, q = 20000.0, 1e-5  # N/m, m: a stiff wall dithering one count
    xs = [0, q, 0, q, 0, q, 0]
    assumed = PassivityController(DT)
    observed = PassivityController(DT, booking="observed")
    for a, b in zip(xs, xs[1:]):
        v = (b - a) / DT
        assumed.update(k * b, v)
        observed.update(k * b, v)
    assert assumed.energy > 0
    assert observed.energy < 0 < assumed.energy


def test_observed_sign_change_of_a_held_control_force_is_what_the_sign_fix_drops():
    seq = [(0.0, 0.01), (3.0, 0.01), (0.0, -0.01)]  # hold 3 N, then reverse under it
    plain = PassivityController(DT, booking="observed")
    fixed = PassivityController(DT, booking="observed", sign_fix=True)
    a = [plain.update(f, v) for f, v in seq]
    b = [fixed.update(f, v) for f, v in seq]
    assert a[:2] == b[:2]
    # reversing under the held 3 N produces 3e-5 J: the plain PC answers it with 3 N
    assert a[2].control == pytest.approx(-3.0)
    assert b[2].control == 0.0 and b[2].energy == pytest.approx(b[1].energy)


def test_bad_booking_and_non_finite_samples():
    with pytest.raises(ControlError, match="booking='zoh'"):
        PassivityController(DT, booking="zoh")
    with pytest.raises(ControlError, match="v=nan"):
        PassivityController(DT).update(1.0, float("nan"))
