"""rolltouch report: a study's outputs as one self-contained HTML page."""

import base64
import re
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import pytest

from bench.montecarlo import read_trials, run_study
from bench.reports.study_page import ReportError, write_report
from bench.study import load_study
from driver.cli import main

ROOT = Path(__file__).resolve().parents[2]
NOISE = ROOT / "bench" / "studies" / "noise"


class Page(HTMLParser):
    """The page's tables (rows of cell texts), its images' sources and its headings."""

    def __init__(self, text):
        super().__init__()
        self.tables, self.images, self.headings, self._cell = [], [], [], None
        self._in = None
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        if tag == "table":
            self.tables.append([])
        elif tag == "tr":
            self.tables[-1].append([])
        elif tag in ("td", "th"):
            self._cell = ""
        elif tag == "img":
            self.images.append(dict(attrs)["src"])
        elif tag in ("h1", "h2"):
            self._in = ""

    def handle_data(self, data):
        if self._cell is not None:
            self._cell += data
        if self._in is not None:
            self._in += data

    def handle_endtag(self, tag):
        if tag in ("td", "th"):
            self.tables[-1][-1].append(self._cell)
            self._cell = None
        elif tag in ("h1", "h2"):
            self.headings.append(self._in)
            self._in = None


def right(row, method):
    return str(row[f"{method}_success"]) in ("1", "True")


@pytest.fixture(scope="module")
def study_dir(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("report")
    f = tmp / "s.toml"
    f.write_text(f'''
name = "small"
parts = ["{ROOT / "parts" / "cam.json"}", "{ROOT / "parts" / "kidney.csv"}"]
rolls_deg = [20.0, 15.0]
methods = ["paper", "reactive"]
engine = "kinematic"
trials = 3
seed = 7
[sweep]
parameter = "noise"
values = ["{NOISE / "paper-x1.toml"}", "{NOISE / "paper-x5.6.toml"}"]
[reactive]
max_rotation_deg = 40.0
''')
    run_study(load_study(f), tmp / "out", workers=1, progress=False)
    return tmp / "out"


def test_the_page_holds_the_study_its_tables_and_its_pictures(study_dir, capsys):
    assert main(["report", str(study_dir)]) == 0
    assert "report.html" in capsys.readouterr().out
    text = (study_dir / "report.html").read_text(encoding="utf-8")
    page = Page(text)
    assert page.headings[0] == "Study small"
    # a table per level, each a row per method, whose right count is the trials.csv's
    rows = read_trials(study_dir / "trials.csv")
    level_tables = [t for t in page.tables if t[0][0] == "method"]
    assert len(level_tables) == 2
    for level, table in enumerate(level_tables):
        assert [r[0] for r in table[1:]] == ["paper", "reactive"]
        for method, row in zip(("paper", "reactive"), table[1:]):
            count = sum(right(r, method) for r in rows if r["level"] == str(level))
            assert row[1].startswith(f"{count}/3 = ")
    # every plot the study wrote, inlined as a PNG
    pngs = sorted(p.name for p in study_dir.glob("*.png"))
    assert len(page.images) == len(pngs) >= 3
    for src in page.images:
        assert src.startswith("data:image/png;base64,")
        assert base64.b64decode(src.split(",", 1)[1])[:8] == b"\x89PNG\r\n\x1a\n"
    # self-contained: nothing fetched from elsewhere
    assert not re.search(r"(src|href)=['\"](?!data:)", text)
    # every trial a method got wrong is listed, the reactive ones with the command that replays them
    wrong = [
        (r["level"], r["trial"], m)
        for r in rows
        for m in ("paper", "reactive")
        if r[f"{m}_success"] not in ("1", "True")
    ]
    assert wrong  # the paper's rule at 5.6 times the noise
    trials = next(t for t in page.tables if t[0][0] == "level")[1:]
    assert sorted((t[0], t[2], t[4]) for t in trials) == sorted(wrong)
    for t in trials:
        if t[4] == "reactive":
            study = study_dir.parent / "s.toml"
            assert (
                t[-1] == f"python -m bench.replay {study} --level {t[0]} --trial {t[2]} --show trial-{t[0]}-{t[2]}.png"
            )


def test_a_folder_without_a_study_is_refused_by_name(tmp_path, capsys):
    assert main(["report", str(tmp_path)]) == 2
    assert "holds no study (study.json missing)" in capsys.readouterr().err
    with pytest.raises(ReportError, match="not a folder"):
        write_report(tmp_path / "nope")


@pytest.mark.skipif(
    not any(shutil.which(b) for b in ("chromium", "chromium-browser", "google-chrome")),
    reason="no headless Chromium on this machine (Debian: apt install chromium) to render the page",
)
def test_the_page_renders_in_a_headless_browser(study_dir, tmp_path):
    write_report(study_dir)
    browser = next(b for b in ("chromium", "chromium-browser", "google-chrome") if shutil.which(b))
    dom = subprocess.run(
        [browser, "--headless", "--no-sandbox", "--disable-gpu", "--dump-dom", (study_dir / "report.html").as_uri()],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    ).stdout
    page = Page(dom)
    assert len([t for t in page.tables if t[0][0] == "method"]) == 2 and page.images
