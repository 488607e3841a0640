"""A study as one page: ``rolltouch report STUDY_DIR`` writes ``STUDY_DIR/report.html``.

One self-contained HTML file (its pictures inlined as data URIs, no script, no outside link) from what
``rolltouch montecarlo`` left in the folder: the study's settings (study.json); per level, a table of
the methods (success with its Wilson interval, sure, sure and wrong, mismatch, rotation, calibration
error); per part, each method's success over the levels; the study's plots (reliability, success
against rotation, ...); and the trials that failed or were sure and wrong, each reactive one with the
command that replays it and draws how its belief narrowed (:mod:`bench.replay` ``--show``).
"""

from __future__ import annotations

import base64
import html
import json
import math
import os
from pathlib import Path
from typing import Any

from localizer import RolltouchError

__all__ = ["ReportError", "write_report", "MAX_LISTED"]

#: The most failed or sure-and-wrong trials listed (the rest are counted).
MAX_LISTED = 60
#: The study's plots shown, in this order when present (any other PNG of the folder follows).
PLOTS = ("methods.png", "success.png", "reliability.png", "errors.png", "failures.png", "bound.png")


class ReportError(RolltouchError, FileNotFoundError):
    """A folder that holds no study's outputs (no study.json and summary.json), or damaged ones."""


def _read_json(path: Path) -> Any:
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ReportError(
            f"{path.parent}: holds no study ({path.name} missing); run 'rolltouch montecarlo STUDY --out "
            f"{path.parent}' first"
        ) from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ReportError(f"{path}: not a study's output ({exc})") from None


def _cell(value: object) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "–"
    if isinstance(value, float):
        return f"{value:.3g}"
    return html.escape(str(value))


def _table(head: list[str], rows: list[list[object]], cls: str = "") -> str:
    out = [f'<table class="{cls}"><thead><tr>' + "".join(f"<th>{html.escape(h)}</th>" for h in head) + "</tr></thead>"]
    out.append("<tbody>")
    for row in rows:
        out.append("<tr>" + "".join(f"<td>{_cell(v)}</td>" for v in row) + "</tr>")
    out.append("</tbody></table>")
    return "".join(out)


def _rate(k: int, n: int, ci: list[float | None] | None) -> str:
    if not n:
        return "–"
    text = f"{k}/{n} = {100 * k / n:.1f}%"
    if ci and all(isinstance(v, (int, float)) for v in ci):
        lo, hi = ci
        text += f" ({100 * float(lo):.1f}–{100 * float(hi):.1f}%)"  # type: ignore[arg-type]
    return text


def _level_table(level: dict[str, Any]) -> str:
    rows = []
    for name, m in level.get("methods", {}).items():
        cal = m.get("calibration") or {}
        rows.append(
            [
                name,
                _rate(int(m.get("success", 0)), int(m.get("trials", 0)), m.get("ci95")),
                m.get("confident"),
                m.get("confident_wrong"),
                m.get("mismatch"),
                m.get("median_rotation_deg"),
                m.get("error_median_mm"),
                cal.get("error"),
            ]
        )
    head = ["method", "right (95% CI)", "sure", "sure and wrong", "mismatch", "median rotation °", "median error mm"]
    return _table([*head, "calibration error"], rows, "methods")


def _part_table(levels: list[dict[str, Any]]) -> str:
    methods = list(levels[0].get("methods", {})) if levels else []
    parts: dict[str, dict[str, list[int]]] = {}
    for level in levels:
        for name in methods:
            for part, c in (level["methods"].get(name, {}).get("per_part") or {}).items():
                k_n = parts.setdefault(part, {}).setdefault(name, [0, 0])
                k_n[0] += int(c.get("success", 0))
                k_n[1] += int(c.get("trials", 0))
    rows: list[list[object]] = []
    for part, counts in sorted(parts.items()):
        row: list[object] = [part]
        row += [f"{counts[m][0]}/{counts[m][1]}" if m in counts else "–" for m in methods]
        rows.append(row)
    return _table(["part", *methods], rows, "parts")


def _trials(folder: Path, study: dict[str, Any], methods: list[str]) -> str:
    from ..montecarlo import read_trials

    csv = folder / "trials.csv"
    if not csv.exists():
        return "<p>No trials.csv in the folder.</p>"
    listed: list[list[object]] = []
    more = 0
    source = study.get("source") or "STUDY.toml"
    for row in read_trials(csv):
        for name in methods:
            stopped = row.get(f"{name}_stopped") or ""
            right = str(row.get(f"{name}_success", "")).lower() in ("1", "true")
            sure_wrong = stopped == "confident" and not right
            if right and not sure_wrong:
                continue
            if len(listed) >= MAX_LISTED:
                more += 1
                continue
            what = "sure and wrong" if sure_wrong else f"not right ({stopped or 'fixed'})"
            level, trial = row.get("level"), row.get("trial")
            show = f"--show trial-{level}-{trial}.png"
            replay = (
                f"python -m bench.replay {source} --level {level} --trial {trial} {show}" if name == "reactive" else ""
            )
            listed.append(
                [
                    level,
                    row.get("value"),
                    trial,
                    Path(str(row.get("part", ""))).name,
                    name,
                    what,
                    _number(row.get(f"{name}_error_mm")),
                    _number(row.get(f"{name}_mass")),
                    replay,
                ]
            )
    if not listed:
        return "<p>Every trial of every method was right.</p>"
    head = ["level", "value", "trial", "part", "method", "outcome", "error mm", "stated", "replay"]
    note = f"<p>{more} more not listed.</p>" if more else ""
    return _table(head, listed, "trials") + note


def _number(text: object) -> float | None:
    try:
        return float(text)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return None


def _images(folder: Path) -> str:
    names = [n for n in PLOTS if (folder / n).exists()]
    names += sorted(p.name for p in folder.glob("*.png") if p.name not in names)
    out = []
    for name in names:
        data = base64.b64encode((folder / name).read_bytes()).decode("ascii")
        out.append(f'<figure><img alt="{html.escape(name)}" src="data:image/png;base64,{data}"><figcaption>')
        out.append(f"{html.escape(name)}</figcaption></figure>")
    return "".join(out) or "<p>No plots in the folder.</p>"


STYLE = """
body { font-family: system-ui, sans-serif; margin: 1.5em auto; max-width: 78em; color: #222; }
table { border-collapse: collapse; margin: 0.5em 0 1.5em; font-size: 0.92em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: right; }
th { background: #f2f2f2; } td:first-child, th:first-child { text-align: left; }
table.trials td:last-child { font-family: monospace; font-size: 0.85em; text-align: left; }
figure { display: inline-block; margin: 0.5em; } img { max-width: 37em; border: 1px solid #ddd; }
pre { background: #f7f7f7; padding: 0.6em; overflow-x: auto; font-size: 0.85em; }
"""


def write_report(folder: str | os.PathLike[str]) -> Path:
    """Write ``folder/report.html`` from a study's outputs; returns its path.

    Raises
    ------
    ReportError
        The folder holds no study (no study.json or summary.json), or they are damaged.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise ReportError(f"{folder}: not a folder; give the --out folder of 'rolltouch montecarlo'")
    study = _read_json(folder / "study.json")
    summary = _read_json(folder / "summary.json")
    if not isinstance(study, dict) or not isinstance(summary, dict) or not isinstance(summary.get("levels"), list):
        raise ReportError(f"{folder}: study.json or summary.json is not a study's (no levels)")
    levels = summary["levels"]
    methods = list(levels[0].get("methods", {})) if levels else []
    title = f"Study {study.get('name', folder.name)}"
    settings = {k: v for k, v in study.items() if k not in ("fingerprints",)}
    parts = [
        f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>{html.escape(title)}</title>",
        f"<style>{STYLE}</style></head><body><h1>{html.escape(title)}</h1>",
        f"<p>{len(study.get('parts', []))} parts, {study.get('trials')} trials per level, methods "
        f"{html.escape(', '.join(methods))}, engine {html.escape(str(study.get('engine')))}, success within "
        f"{_cell(study.get('success_radius'))} mm; from {html.escape(str(study.get('source')))}.</p>",
    ]
    for level in levels:
        name = f"{level.get('parameter') or 'level'} = {level.get('value')}" if level.get("parameter") else "all trials"
        parts.append(f"<h2>Level {level.get('level')}: {html.escape(str(name))}</h2>")
        parts.append(_level_table(level))
    parts.append("<h2>Per part (all levels)</h2>" + _part_table(levels))
    parts.append("<h2>Plots</h2>" + _images(folder))
    parts.append("<h2>Trials not right, or sure and wrong</h2>" + _trials(folder, study, methods))
    parts.append("<h2>Settings (study.json)</h2><pre>" + html.escape(json.dumps(settings, indent=1)) + "</pre>")
    parts.append("</body></html>")
    out = folder / "report.html"
    try:
        out.write_text("\n".join(parts), encoding="utf-8")
    except OSError as exc:
        raise ReportError(f"cannot write {out}: {exc.strerror or exc}") from None
    return out
