"""The documents' links lead somewhere inside the repository."""

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
LINK = re.compile(r"\]\(([^)\s]+)\)|src=\"([^\"]+)\"")


def _links(doc: Path):
    for m in LINK.finditer(doc.read_text(encoding="utf-8")):
        target = m.group(1) or m.group(2)
        if re.match(r"^[a-z]+:", target) or target.startswith("#"):
            continue
        yield target.split("#")[0]


@pytest.mark.parametrize("doc", DOCS, ids=lambda p: p.name)
def test_every_relative_link_resolves_inside_the_repository(doc):
    bad = []
    for target in _links(doc):
        path = (doc.parent / target).resolve()
        if ROOT not in path.parents and path != ROOT or not path.exists():
            bad.append(target)
    assert not bad, f"{doc.name}: links that lead nowhere or outside the repository: {bad}"
