"""Worlds whose part is not its model (issue 29): defects, scale, a part of its own, spikes."""

import math
from pathlib import Path

import numpy as np
import pytest

from localizer import load_part, part_from_points
from sim2d import Defect, NoiseModel, SimError, SimRig, WheelRig, WorldChange, WorldSpec, load_world, world_part
from sim2d.sampled import SampledPart, model_params, model_sample

PARTS = Path(__file__).resolve().parents[2] / "parts"


@pytest.fixture(scope="module")
def trefoil():
    return load_part(PARTS / "trefoil.json")


def normal_offset(part, sampled):
    """Each sample point's offset from the model point it is tagged with, along the model's outward normal."""
    _, xy, normal = model_sample(part, 1.0)
    theta = np.asarray(part.tangent_angle_at_arc(sampled.arcs))
    n = np.stack([np.sin(theta), -np.cos(theta)], axis=-1)
    return np.einsum("ij,ij->i", sampled.xy - np.asarray(part.point_at_arc(sampled.arcs)), n)


def test_a_defect_is_smooth_and_as_high_and_long_as_asked():
    d = Defect(arc=10.0, height=0.3, length=4.0)
    s = np.linspace(5.0, 15.0, 100001)
    h = d.offset(s, 100.0)
    assert h.max() == pytest.approx(0.3, abs=1e-9) and s[np.argmax(h)] == pytest.approx(10.0, abs=1e-4)
    assert np.all(h[np.abs(s - 10.0) >= 2.0] == 0.0)
    # smooth: slope and curvature vanish at its ends (finite differences across the ends stay small)
    ds = s[1] - s[0]
    slope = np.diff(h) / ds
    assert np.max(np.abs(np.diff(slope) / ds)) < 0.75  # |h''| of cos⁴: 4·h·(π/ℓ)² = 0.74 /mm
    assert np.max(np.abs(slope)) == pytest.approx(4 * 0.3 * math.pi / 4 * (3**1.5 / 16), rel=1e-3)
    # across the first point of the part
    wrapped = Defect(arc=99.0, height=-0.2, length=4.0).offset(np.array([0.5, 1.1, 97.0]), 100.0)
    assert wrapped[0] < 0 and wrapped[1] == 0.0 and wrapped[2] == 0.0


def test_the_world_is_the_machined_model_where_nothing_differs(trefoil):
    noise = NoiseModel(machining_error=0.01)
    a = world_part(trefoil, WorldChange(), noise, np.random.default_rng(4))
    b = world_part(trefoil, WorldChange(spike_rate=0.5, spike_size=20.0), noise, np.random.default_rng(4))
    assert not isinstance(a, SampledPart) and np.array_equal(a.points, b.points)


def test_a_bump_is_added_along_the_models_normal_on_top_of_the_machining(trefoil):
    bump = Defect(arc=120.0, height=0.3, length=4.0)
    world = world_part(trefoil, WorldChange(defects=(bump,)), NoiseModel(), np.random.default_rng(0))
    assert isinstance(world, SampledPart) and world.altered
    off = normal_offset(trefoil, world)
    expected = bump.offset(world.arcs, trefoil.perimeter)
    assert np.max(np.abs(off - expected)) < 1e-9
    # with machining: the same machined part as the clean world, plus the bump
    noise = NoiseModel(machining_error=0.02)
    clean = world_part(trefoil, WorldChange(scale=1.0), noise, np.random.default_rng(7))
    bumped = world_part(trefoil, WorldChange(defects=(bump,)), noise, np.random.default_rng(7))
    far = np.abs(np.asarray(trefoil.arc_offset(bumped.arcs, 120.0))) > 3.0
    on_clean = clean.point(trefoil.param_at_arc(bumped.arcs[far]))
    assert np.max(np.hypot(*(bumped.xy[far] - on_clean).T)) < 1e-9


def test_a_scaled_part_grows_about_its_centroid(trefoil):
    world = world_part(trefoil, WorldChange(scale=1.02), NoiseModel(), np.random.default_rng(0))
    model_xy = np.asarray(trefoil.point_at_arc(world.arcs))
    c = (world.xy - 1.02 * model_xy) / (1 - 1.02)  # the fixed point of the scaling, at every sample
    assert np.ptp(c, axis=0).max() < 1e-9
    a = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    disc = part_from_points(30 * np.c_[np.cos(a), np.sin(a)] + [5.0, -2.0])
    world = world_part(disc, WorldChange(scale=0.98), NoiseModel(), np.random.default_rng(0))
    assert np.allclose(world.xy.mean(axis=0), [5.0, -2.0], atol=1e-3)
    assert np.allclose(np.hypot(*(world.xy - [5.0, -2.0]).T), 0.98 * 30, atol=1e-3)


def test_a_dent_that_would_cut_through_the_part_is_refused_by_name():
    a = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    sliver = part_from_points(np.c_[40 * np.cos(a), 0.6 * np.sin(a)], name="sliver")
    dent = Defect(arc=sliver.perimeter / 4, height=-1.5, length=6.0)
    with pytest.raises(SimError, match=r"sliver with a 1.5 mm dent 6 mm long at arc .* crosses itself"):
        world_part(sliver, WorldChange(defects=(dent,)), NoiseModel(), np.random.default_rng(0))
    with pytest.raises(SimError, match="higher than it is long"):
        WorldChange(defects=(Defect(1.0, 3.0, 2.0),))


def test_a_part_of_its_own_is_tagged_with_the_models_arcs(trefoil):
    # the model resampled: the same curve through other points, within microns of it
    arcs = np.linspace(0.0, trefoil.perimeter, 150, endpoint=False) + 0.7
    resampled = part_from_points(trefoil.point_at_arc(arcs), name="resampled")
    world = world_part(trefoil, WorldChange(part=resampled), NoiseModel(), np.random.default_rng(0))
    assert isinstance(world, SampledPart) and world.altered
    # each point lies within microns of the model point it is tagged with
    gap = np.hypot(*(world.xy - np.asarray(trefoil.point_at_arc(world.arcs))).T)
    assert np.max(gap) < 0.05 and np.median(gap) < 0.005
    assert np.all(np.diff(world.arcs)[np.abs(np.diff(world.arcs)) < trefoil.perimeter / 2] > -1e-3)


def test_the_rigs_contact_on_a_sampled_model_agrees_with_the_spline(trefoil):
    far = Defect(arc=10.0, height=0.05, length=4.0)  # a defect far from where the jaw touches
    plain = SimRig(trefoil, noise="none", seed=1)
    world = SimRig(trefoil, noise="none", seed=1, change=WorldChange(defects=(far,)))
    for arc in (120.0, 140.0, 250.0):
        pose = plain.approach_pose(arc, jaw_position=-10.0, standoff=-0.3)
        for r in (plain, world):
            r.world.set_hand(*pose)
        a, b = plain.truth(), world.truth()
        assert b["contact_arc"] == pytest.approx(a["contact_arc"], abs=0.004)
        assert b["jaw_position"] == pytest.approx(a["jaw_position"], abs=0.004)
        assert b["force"] == pytest.approx(a["force"], rel=0.01)


def test_spikes_hit_the_twist_channel_at_their_rate_and_leave_the_rest_of_the_noise_alone(trefoil):
    rigs = [
        SimRig(trefoil, noise="paper", seed=5, change=WorldChange(spike_rate=rate, spike_size=20.0))
        for rate in (0.0, 0.2)
    ]
    reads = []
    for r in rigs:
        r.move(*r.approach_pose(120.0, jaw_position=-10.0, standoff=-0.3))
        reads.append(np.array([r.read() for _ in range(400)]))
    assert np.array_equal(reads[0][:, 0], reads[1][:, 0])  # v1 untouched, the noise draws the same
    dv2 = reads[1][:, 1] - reads[0][:, 1]
    spiked = np.abs(dv2) > 1e-12
    assert rigs[1].spikes.count == spiked.sum() and 50 < spiked.sum() < 110
    assert np.allclose(np.abs(dv2[spiked]), 20 * 0.0001)
    assert 0.3 < np.mean(dv2[spiked] > 0) < 0.7


def test_a_wheel_rolls_on_the_world_part_too(trefoil):
    from localizer import WheelJaw

    bump = Defect(arc=140.0, height=0.3, length=4.0)
    rig = WheelRig(trefoil, WheelJaw(5.0), noise="none", change=WorldChange(defects=(bump,)))
    plain = WheelRig(trefoil, WheelJaw(5.0), noise="none")
    x, y, phi = plain.approach_pose(140.0, standoff=-0.3)  # against the model: the bump is in the way
    for r in (rig, plain):
        r.world.set_hand(x, y, phi)
    # on the bump's crest the wheel is pushed 0.3 mm further out: the wrist gives 0.3 mm more
    assert rig.world.contact().depth == pytest.approx(plain.world.contact().depth + 0.3, abs=0.01)


def test_a_world_table_is_checked_by_name(tmp_path):
    good = tmp_path / "w.toml"
    good.write_text("[world]\ndefects = 1\ndefect_height_mm = [0.1, 0.5]\ndefect_length_mm = 4.0\n")
    spec = load_world(good)
    assert spec.defects == 1 and spec.defect_height_mm == (0.1, 0.5) and spec.defect_place == "start"
    for text, match in (
        ("[world]\ndefect = 1\n", r"unknown key\(s\) \['defect'\]"),
        ("[world]\ndefects = -1\n", "defects=-1 must be a whole number"),
        ("[world]\ndefect_height_mm = 0\n", "defect_height_mm=0 must be a nonzero"),
        ("[world]\ndefect_height_mm = [0.5, 0.1]\n", "a range is"),
        ("[world]\ndefect_place = 'middle'\n", r"defect_place='middle'; use one of \['start', 'anywhere'\]"),
        ("[world]\nscale = 2.0\n", r"scale=2.0 must be within"),
        ("[world]\nspike_rate = 1.5\n", "spike_rate=1.5 must be a probability"),
        ("[world]\nworld_parts = ['nope.json']\n", "nope.json"),
        ("defects = 1\n", r"give one \[world\] table"),
        ("[world\n", "not valid TOML"),
    ):
        bad = tmp_path / "bad.toml"
        bad.write_text(text)
        with pytest.raises(SimError, match=match):
            load_world(bad)
    two = tmp_path / "two.toml"
    two.write_text(f"[world]\nworld_parts = ['{PARTS / 'cam.json'}']\n")
    with pytest.raises(SimError, match=r"1 file\(s\) for 2 part\(s\)"):
        load_world(two, parts=2)


def test_a_world_draws_its_defects_near_the_start_or_anywhere(trefoil):
    rng = np.random.default_rng(3)
    near = WorldSpec(defects=3, defect_height_mm=(0.1, 0.5), defect_length_mm=6.0, defect_near_mm=5.0)
    change = near.draw(trefoil, 100.0, rng)
    assert len(change.defects) == 3
    for d in change.defects:
        assert abs(d.arc - 100.0) <= 5.0 and 0.1 <= abs(d.height) <= 0.5 and d.length == 6.0
    heights = [d.height for _ in range(40) for d in near.draw(trefoil, 100.0, rng).defects]
    assert min(heights) < 0 < max(heights)
    ranged = WorldSpec(defects=20, defect_length_mm=(2.0, 8.0)).draw(trefoil, 100.0, rng)
    lengths = [d.length for d in ranged.defects]
    assert 2.0 <= min(lengths) < 4.0 < max(lengths) <= 8.0
    anywhere = WorldSpec(defects=50, defect_place="anywhere").draw(trefoil, 100.0, rng)
    assert np.ptp([d.arc for d in anywhere.defects]) > trefoil.perimeter / 2


def test_the_rigs_approach_the_real_part_not_the_model(trefoil):
    # a jaw laid 1 mm off a part made 2% large would already be in it: the approach is off what is there
    from localizer import WheelJaw

    scaled = WorldChange(scale=1.02)
    for rig in (SimRig(trefoil, change=scaled), WheelRig(trefoil, WheelJaw(5.0), change=scaled)):
        pose = rig.approach_pose(120.0) if isinstance(rig, WheelRig) else rig.approach_pose(120.0, standoff=1.0)
        rig.world.set_hand(*pose)
        assert rig.world.contact().force == 0.0


def test_a_models_sample_is_made_once_kept_read_only_and_is_the_models_own(trefoil):
    arcs, xy, normal = model_sample(trefoil, 0.5)
    assert all(a is b for a, b in zip(model_sample(trefoil, 0.5), (arcs, xy, normal)))  # kept
    with pytest.raises(ValueError, match="read-only"):
        xy[0, 0] = 1.0
    # the model's own points, normals and parameters there (computed afresh here)
    assert np.array_equal(arcs, np.arange(0.0, trefoil.perimeter, 0.5))
    assert np.array_equal(xy, trefoil.point_at_arc(arcs))
    theta = np.asarray(trefoil.tangent_angle_at_arc(arcs))
    assert np.array_equal(normal, np.stack([np.sin(theta), -np.cos(theta)], axis=-1))
    assert np.array_equal(model_params(trefoil, 0.5), trefoil.param_at_arc(arcs))
    assert np.array_equal(model_sample(trefoil, 0.25)[0], np.arange(0.0, trefoil.perimeter, 0.25))  # another spacing
    # kept with the model's other tables: dropped with them, and made again the same
    trefoil.forget_tables()
    again = model_sample(trefoil, 0.5)
    assert again[1] is not xy and np.array_equal(again[1], xy)
