"""The Table-2-style table in CSV, Markdown, LaTeX and HTML.

Failed conditions stay in the table as rows with their message, so a report
never hides what did not run.
"""

from __future__ import annotations

import html
import math
from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from cageless.atomic import atomic_write_text
from cageless.outputs import versioned_csv
from cageless.comparison.compare import SLIP_REFERENCES, ComparisonRow
from cageless.comparison.metrics import SLIP_RATE_DEFINITION

__all__ = ["table_frame", "number_cell", "slip_reference_note", "to_csv", "to_markdown", "to_latex", "to_html", "write_tables",
           "HEADERS", "SE_COLUMNS", "SE_NOTE"]

HEADERS = {
    "speed_rpm": "Speed (r/min)", "radial_load_n": "Radial load (N)", "axial_load_n": "Axial load (N)",
    "theoretical_slip_pct": "Theoretical slip (%)", "experimental_slip_pct": "Experimental slip (%)",
    "mae_pp": "MAE (pp)", "rmse_pp": "RMSE (pp)", "max_error_pp": "Max error (pp)",
}


def table_frame(rows: Sequence[ComparisonRow]) -> pd.DataFrame:
    """The rows as a frame, sorted by speed then loads; ``label``, ``status``, ``message`` and
    ``slip_reference`` (a key of :data:`~cageless.comparison.compare.SLIP_REFERENCES`) kept."""
    frame = pd.DataFrame([r.to_dict() for r in rows],
                         columns=[*HEADERS, "label", "status", "message", "slip_reference", *SE_COLUMNS.values()])
    return frame.sort_values(["speed_rpm", "radial_load_n", "axial_load_n", "label"], kind="stable").reset_index(
        drop=True)


#: The standard error column of each slip-rate column (shown as "value ± se" in the readable tables).
SE_COLUMNS = {"theoretical_slip_pct": "theoretical_slip_se_pp", "experimental_slip_pct": "experimental_slip_se_pp"}

#: Printed under every table with standard errors.
SE_NOTE = ("± is the slip rate's standard error from the balls it was taken over (a bootstrap over the balls): "
           "how far other balls, or a longer clip, could move it. It holds no tracking or model error.")


def _labelled(frame: pd.DataFrame) -> bool:
    """Whether the rows carry labels (the report's video names): then the tables show them in a first column, so
    two videos at one condition are told apart."""
    return bool(frame["label"].fillna("").astype(str).str.len().gt(0).any())


def _headers(frame: pd.DataFrame) -> list[str]:
    return (["Video"] if _labelled(frame) else []) + list(HEADERS.values())


def number_cell(value: float, fmt: str = "g") -> str:
    """A table cell: blank for a value that is not known (NaN), e.g. a failed video's unread speed."""
    return format(value, fmt) if isinstance(value, int | float) and math.isfinite(value) else ""


def _cells(frame: pd.DataFrame) -> list[list[str]]:
    out = []
    labelled = _labelled(frame)
    for _, r in frame.iterrows():
        cells = [str(r["label"] or "")] if labelled else []
        cells += [number_cell(r[c], "g") for c in ("speed_rpm", "radial_load_n", "axial_load_n")]
        if r["status"] == "failed":
            cells += ["failed"] + [""] * 4
        else:
            cells += [_with_se(r, c) for c in list(HEADERS)[3:]]
        out.append(cells)
    return out


def _with_se(r: pd.Series, column: str) -> str:
    """A value cell, with `` ± se`` after a slip rate whose standard error is known."""
    cell = number_cell(r[column], ".2f")
    se = r.get(SE_COLUMNS.get(column, ""), float("nan"))
    return f"{cell} ± {se:.2f}" if cell and isinstance(se, float) and math.isfinite(se) else cell


def _notes(frame: pd.DataFrame) -> list[str]:
    notes = [SLIP_RATE_DEFINITION, slip_reference_note(frame)]
    if any(frame[c].notna().any() for c in SE_COLUMNS.values()):
        notes.append(SE_NOTE)
    for _, r in frame.iterrows():
        if r["status"] != "ok":
            where = (f" ({number_cell(r['speed_rpm'], 'g')} r/min, {number_cell(r['radial_load_n'], 'g')} N)"
                     if math.isfinite(r["speed_rpm"]) else "")
            notes.append(f"{r['label'] or 'condition'}{where}: {r['status']}: {r['message']}")
    return notes


def slip_reference_note(frame: pd.DataFrame) -> str:
    """One sentence naming what the rows' slip rates are referred to (per row when they differ)."""
    refs = frame.loc[frame["status"] != "failed", "slip_reference"].dropna().unique().tolist() or ["cage"]
    if len(refs) == 1:
        return f"Slip reference: {SLIP_REFERENCES.get(refs[0], refs[0])}."
    return "Slip reference per row (column slip_reference): " + "; ".join(
        f"{k}: {SLIP_REFERENCES.get(k, k)}" for k in refs) + "."


def to_csv(frame: pd.DataFrame) -> str:
    """Machine-readable CSV with the raw column names, and the ``software_version`` that wrote it last."""
    return versioned_csv(frame, "%.6g")


def to_markdown(frame: pd.DataFrame) -> str:
    """A Markdown table with the definition and any failures as notes."""
    headers = _headers(frame)
    lines = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
    lines += ["| " + " | ".join(c) + " |" for c in _cells(frame)]
    return "\n".join(lines + [""] + [f"Note: {n}" for n in _notes(frame)]) + "\n"


def _tex(text: str) -> str:
    for a, b in (("\\", r"\textbackslash{}"), ("%", r"\%"), ("&", r"\&"), ("_", r"\_"), ("#", r"\#"),
                 ("±", r"$\pm$")):
        text = text.replace(a, b)
    return text


def to_latex(frame: pd.DataFrame) -> str:
    """A LaTeX ``tabular`` (booktabs) with the notes below."""
    headers = _headers(frame)
    head = " & ".join(_tex(h) for h in headers)
    body = "\n".join(" & ".join(_tex(c) for c in cells) + r" \\" for cells in _cells(frame))
    notes = "\n".join(r"\par\footnotesize " + _tex(n) for n in _notes(frame))
    columns = ("l" if len(headers) > len(HEADERS) else "") + "r" * len(HEADERS)
    return (r"\begin{tabular}{" + columns + "}\n\\toprule\n" + head + r" \\" + "\n\\midrule\n" + body
            + "\n\\bottomrule\n\\end{tabular}\n" + notes + "\n")


def to_html(frame: pd.DataFrame) -> str:
    """An HTML table (a fragment for the report, escaped)."""
    head = "".join(f"<th>{html.escape(h)}</th>" for h in _headers(frame))
    rows = []
    for (_, r), cells in zip(frame.iterrows(), _cells(frame), strict=True):
        cls = "" if r["status"] == "ok" else f' class="{html.escape(r["status"].replace(" ", "-"))}"'
        rows.append(f"<tr{cls}>" + "".join(f"<td>{html.escape(c)}</td>" for c in cells) + "</tr>")
    notes = "".join(f"<p class='note'>{html.escape(n)}</p>" for n in _notes(frame))
    return f"<table class='slip'><thead><tr>{head}</tr></thead><tbody>{''.join(rows)}</tbody></table>{notes}"


def write_tables(rows: Sequence[ComparisonRow], stem: str | Path) -> dict[str, Path]:
    """Write ``<stem>.csv``, ``.md``, ``.tex`` and ``.html`` atomically; returns the paths."""
    frame = table_frame(rows)
    stem = Path(stem)
    out = {}
    for ext, text in (("csv", to_csv(frame)), ("md", to_markdown(frame)), ("tex", to_latex(frame)),
                      ("html", to_html(frame))):
        path = stem.with_suffix(f".{ext}")
        atomic_write_text(path, text)
        out[ext] = path
    return out
