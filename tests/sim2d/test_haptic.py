"""The one-axis sampled device: physics against closed forms, and the passivity study's findings."""

import numpy as np
import pytest

from passivity import PassivityController
from sim2d import SimError
from sim2d.haptic import Axis, Operator, Servo, simulate_servo, simulate_wall


def test_a_free_axis_follows_the_closed_form_of_a_damped_mass():
    axis = Axis(mass=0.1, damping=5.0, substeps=50)
    servo = Servo(gain=0.0, start=-1.0, duration=0.2)  # the part is 1 m away: a constant 1 N push
    tr = simulate_servo(servo, axis=axis)
    tau, vt = 0.1 / 5.0, 1.0 / 5.0
    expected = -1.0 + vt * (tr.time - tau * (1 - np.exp(-tr.time / tau)))
    assert np.max(np.abs(tr.position - expected)) < 1e-4 * vt * tr.time[-1] + 1e-6  # semi-implicit Euler


def test_encoder_quantizes_and_velocity_is_its_difference():
    axis = Axis(resolution=1e-5)
    tr = simulate_wall(None, axis=axis)
    counts = tr.encoder / axis.resolution
    assert np.allclose(counts, np.round(counts), atol=1e-6)
    assert np.all(tr.encoder <= tr.position + 1e-15) and np.all(tr.position - tr.encoder < axis.resolution)
    assert np.allclose(tr.velocity[1:], np.diff(tr.encoder) / axis.dt)


def test_the_bare_wall_holds_the_operator_push_on_average():
    op = Operator()
    tr = simulate_wall(None, operator=op)
    _, t0, t1 = op.phases[1]
    sel = (tr.time >= t0) & (tr.time < t1)
    push = op.stiffness * (op.depth - tr.position[sel].mean())
    assert tr.contact_force[sel].mean() == pytest.approx(push, rel=0.05)


def _pc(**fixes):
    return PassivityController(1e-3, booking="observed", **fixes)


def test_plain_pc_is_noisy_at_low_velocity_and_the_sign_fix_and_both_fixes_quiet_it():
    plain = simulate_wall(_pc())
    sign = simulate_wall(_pc(sign_fix=True))
    both = simulate_wall(_pc(sign_fix=True, hold_fix=True))
    assert plain.noise() > 20 * sign.noise() and plain.noise() > 20 * both.noise()
    for tr in (plain, sign, both):
        assert tr.energy[-1] >= -1e-12  # passivity kept at the end
    assert both.energy.min() > -1e-4 and sign.energy.min() > -1e-4
    assert plain.energy.min() < -1e-3  # what the plain PC cannot dissipate


def test_the_assumed_booking_sees_a_sampled_wall_as_passive():
    tr = simulate_wall(PassivityController(1e-3))
    assert np.all(tr.energy >= 0) and np.all(tr.control == 0)


def test_guarded_servo_keeps_contact_where_the_bare_servo_chatters():
    servo = Servo(gain=20.0, duration=0.6)
    bare = simulate_servo(servo)
    guarded = simulate_servo(servo, _pc(sign_fix=True, hold_fix=True))
    tail = bare.time >= 0.3
    assert np.sum(bare.contact_force[tail] == 0) > 50  # loses the part every cycle
    assert np.all(guarded.contact_force[tail] > 0.5)
    assert abs(guarded.contact_force[tail].mean() - servo.target) < 0.05


def test_a_gentle_servo_is_left_alone_by_the_guard():
    servo = Servo(gain=2.0, duration=0.5)
    bare = simulate_servo(servo)
    guarded = simulate_servo(servo, _pc(sign_fix=True, hold_fix=True))
    tail = bare.time >= 0.25
    for tr in (bare, guarded):
        assert np.all(np.abs(tr.contact_force[tail] - servo.target) < 0.01)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"mass": 0}, "Axis.mass=0"),
        ({"damping": -1}, "Axis.damping=-1"),
        ({"substeps": 0}, "Axis.substeps=0"),
    ],
)
def test_bad_axis(kwargs, match):
    with pytest.raises(SimError, match=match):
        Axis(**kwargs)


def test_bad_servo_and_wall():
    with pytest.raises(SimError, match="Servo.gain=-1"):
        Servo(gain=-1)
    with pytest.raises(SimError, match="wall_stiffness=0"):
        simulate_wall(None, wall_stiffness=0)
