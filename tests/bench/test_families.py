"""The generated part families: fixed by their seed, valid parts of every kind, the shipped files current."""

import json
from pathlib import Path

import numpy as np
import pytest

from bench.families import HELDOUT_A_SEED, HELDOUT_SEED, KINDS, TUNING_SEED, family, write_family
from localizer import load_part

ROOT = Path(__file__).resolve().parents[2]


def test_a_family_is_a_function_of_its_seed(tmp_path):
    a, b = family(7, 4), family(7, 4)
    assert a == b and [d["name"].split("-")[0] for d in a] == list(KINDS)
    assert family(8, 4) != a
    for p in write_family(7, 4, tmp_path):
        part = load_part(p)
        assert 36 <= part.n_knots <= 90 and part.perimeter > 100.0


@pytest.mark.parametrize(
    "folder, seed, count",
    [("tuning", TUNING_SEED, 24), ("heldout-a", HELDOUT_A_SEED, 24), ("heldout-b", HELDOUT_SEED, 24)],
)
def test_the_shipped_families_are_what_their_seed_gives(folder, seed, count):
    shipped = sorted((ROOT / "bench" / "parts" / folder).glob("*.json"))
    assert len(shipped) == count
    made = {d["name"]: d for d in family(seed, count)}
    for p in shipped:
        doc = json.loads(p.read_text())
        assert np.allclose(doc["points"], made[doc["name"]]["points"], atol=1e-9), p.name
