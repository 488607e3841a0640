import math

import numpy as np
import pytest

from localizer import load_part
from sim2d import SimError
from sim2d.machining import machined_part, machining_slope
from sim2d.noise import PRESETS, NoiseModel, load_noise
from sim2d.wrist import Wrist, encoder_angle


def test_wrist_ratio_is_eq_13():
    w = Wrist()
    d = np.linspace(-50, 50, 11)
    s1, s2 = w.stresses(2.0, d)
    # W2 = 2 W1 = 8 δ up to the paper's rounding of the dimensions (3.175, 6.35, 0.794 mm)
    assert np.allclose(s2 / s1, -d / (32 * w.height), rtol=1e-3)
    v1, v2 = w.ideal_voltages(1.0, d)
    assert np.allclose(v1, 0.4) and np.allclose(v2 / v1, s2 / s1)


def test_eq_10_and_12_by_hand():
    w = Wrist(w1=4.0, w2=8.0, delta=1.0, height=20.0)
    s1, s2 = w.stresses(3.0, 10.0)
    assert s1 == pytest.approx(-6 * 3.0 * 20.0 / (4.0 * 1.0))
    assert s2 == pytest.approx(3 * 3.0 * 10.0 / (64.0 * 1.0))


def test_noise_free_voltages_and_noisy_statistics():
    w = Wrist()
    rng = np.random.default_rng(0)
    v1, v2 = w.voltages(np.ones(4), np.zeros(4), np.zeros(4), PRESETS["none"], rng)
    assert np.allclose(v1, 0.4) and np.allclose(v2, 0.0)
    noise = NoiseModel(v1_noise=0.01, v1_offset=0.1, v1_drift=0.001)
    v1, _ = w.voltages(np.ones(20000), np.zeros(20000), np.full(20000, 10.0), noise, rng)
    assert v1.mean() == pytest.approx(0.4 + 0.1 + 0.01, abs=5e-4)
    assert v1.std() == pytest.approx(0.01, rel=0.05)
    q = NoiseModel(adc_step=0.01)
    v1, _ = w.voltages(np.array([1.0]), np.array([0.0]), np.array([0.0]), q, rng)
    assert v1[0] / 0.01 == pytest.approx(round(v1[0] / 0.01))


def test_encoder_quantization():
    noise = PRESETS["paper"]
    phi = np.linspace(0, 1, 1001)
    q = encoder_angle(phi, noise)
    assert np.abs(q - phi).max() <= math.radians(0.03) / 2 + 1e-15
    assert encoder_angle(0.123, PRESETS["none"]) == 0.123


def test_load_noise_presets_and_toml(tmp_path):
    assert load_noise("none") == NoiseModel()
    f = tmp_path / "n.toml"
    f.write_text('preset = "paper"\nv2_noise = 0.002\n')
    n = load_noise(f)
    assert n.v2_noise == 0.002 and n.encoder_step == PRESETS["paper"].encoder_step
    assert PRESETS["paper"].scaled(v2_noise=2.0).v2_noise == 2 * PRESETS["paper"].v2_noise


@pytest.mark.parametrize(
    "text, match",
    [
        ("v2_noize = 1.0\n", r"unknown key\(s\) \['v2_noize'\]"),
        ("v2_noise = -1.0\n", "v2_noise=-1.0 must be >= 0"),
        ('v2_noise = "a"\n', "must be a finite number"),
        ('preset = "lab"\n', "unknown preset 'lab'"),
        ("v2_noise = \n", "not valid TOML"),
        # every input bounded: a noise file is a few lines, a large one is not read into memory
        ("# " + "x" * 70_000 + "\n", "a noise file may have"),
    ],
)
def test_bad_noise_files(tmp_path, text, match):
    f = tmp_path / "bad.toml"
    f.write_text(text)
    with pytest.raises(SimError, match=match):
        load_noise(f)


def test_a_noise_file_that_is_not_text_is_named(tmp_path):
    f = tmp_path / "bin.toml"
    f.write_bytes(b"\xff\xfe\x00 preset")
    with pytest.raises(SimError, match="bin.toml: not a text file"):
        load_noise(f)


def test_bad_noise_spec():
    with pytest.raises(SimError, match="use a preset"):
        load_noise("lab")
    with pytest.raises(SimError, match="no field 'x'"):
        PRESETS["paper"].scaled(x=2.0)


def test_machining_slope_of_one_harmonic():
    # one harmonic: amplitude √2·rms, slope amplitude √2·rms·2π/P, slope RMS rms·2π/P
    assert machining_slope(0.01, 100.0, 100.0) == pytest.approx(0.01 * 2 * math.pi / 100.0)
    assert machining_slope(0.0, 20.0, 300.0) == 0.0


def test_machining_error_is_smooth_and_of_the_stated_size():
    part = load_part("parts/trefoil.json")
    rng = np.random.default_rng(3)
    real = machined_part(part, NoiseModel(machining_error=0.05), rng)
    dev = np.einsum("ij,ij->i", real.points - part.points, part.normal(np.arange(part.n_knots, dtype=float)))
    assert np.sqrt(np.mean(dev**2)) == pytest.approx(0.05, rel=1e-6)
    assert np.abs(np.diff(dev)).max() < 0.05  # smooth: neighbouring knots move alike
    assert machined_part(part, NoiseModel(), rng) is part
