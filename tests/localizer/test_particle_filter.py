"""The particle filter: against the grid filter, which is exact on its grid, and its settings."""

import math
from pathlib import Path

import numpy as np
import pytest

from localizer import ContactFilter, ParticleFilter, QueryError, load_part

PARTS = Path(__file__).resolve().parents[2] / "parts"
STEP = math.radians(0.2)


@pytest.fixture(scope="module")
def cam():
    return load_part(PARTS / "cam.json")


def readings(flt, start_arc, turns, rng, sd):
    """Cumulative arcs a true start would give (from the grid filter's tracks), plus noise."""
    i = int(round(start_arc / flt.tracks.h)) % flt.grid.size
    arcs, ok = flt.tracks.advance(np.full(len(turns), i), np.asarray(turns))
    assert ok.all()
    e = sd * rng.standard_normal(len(turns) + 1)
    return arcs - flt.grid[i] + e[1:] - e[0], arcs


def test_many_particles_agree_with_the_grid_filter(cam):
    rng = np.random.default_rng(11)
    grid = ContactFilter(cam, sd_position=0.04, sd_scale=0.0, sd_slope=0.0)
    pf = ParticleFilter(cam, particles=60000, sd_position=0.04, process=0.0005, seed=3)
    turns = STEP * np.arange(1, 176)
    z, arcs = readings(grid, 200.0, turns, rng, 0.04)
    for a, t in zip(z, turns):
        grid.update(float(a), float(t))
        pf.update(float(a), float(t))
    b = grid.belief()
    est, mass = pf.estimate()
    assert abs(cam.arc_offset(est, b.map_arc)) < 0.15
    assert mass == pytest.approx(b.mass, abs=0.2)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"particles": 1}, "particles=1"),
        ({"particles": 10**9}, r"particles=1000000000 must be a whole number from 2 to 262144"),
        ({"particles": 2.5}, "particles=2.5"),
        ({"sd_position": 0}, "sd_position=0"),
        ({"process": -1.0}, "process=-1.0"),
    ],
)
def test_bad_particle_filter_settings(cam, kwargs, match):
    with pytest.raises(QueryError, match=match):
        ParticleFilter(cam, **kwargs)
