"""The gallery's contact sheets (a grid of pictures per sheet, each labelled with its preset
and mean chroma) and its table in Markdown, written between markers of a page whose
other text (what the pictures show, written by a person) is kept."""

from __future__ import annotations

import io
import math
from pathlib import Path
from typing import Any

from opaline.output.files import write_atomic

COLUMNS = 4
LABEL = 20
GAP = 4
BEGIN = "<!-- gallery-table: written by `opaline gallery`; edits between these lines are lost -->"
END = "<!-- gallery-table: end -->"
PAGE_HEAD = """# Gallery

Every preset, and real meshes with a set of presets, under the built-in studio and under
their default lighting, with the mean CIELAB chroma C\\*ab and lightness L\\* over the
object's pixels (display sRGB, D65; the object's pixels are those a transparent render
covers), and the mean C\\*ab of the backdrop around it (a film that lets the backdrop through
carries some of its chroma).

"""


def sheet_name(sheet: str) -> str:
    return f"sheet-{sheet}.png"


def write_sheets(out: Path, rows: list[dict[str, Any]]) -> list[str]:
    """One PNG per sheet: its pictures in a grid, in the order rendered."""
    sheets: dict[str, list[dict[str, Any]]] = {}
    for row in rows:
        sheets.setdefault(row["sheet"], []).append(row)
    written = []
    for sheet, shown in sheets.items():
        write_atomic(out / sheet_name(sheet), contact_sheet(out, shown))
        written.append(sheet_name(sheet))
    return written


def contact_sheet(out: Path, rows: list[dict[str, Any]]) -> bytes:
    from PIL import Image, ImageDraw, ImageFont

    images = [Image.open(out / row["image"]).convert("RGB") for row in rows]
    cell_w = max(image.width for image in images) + GAP
    cell_h = max(image.height for image in images) + LABEL + GAP
    columns = min(COLUMNS, len(images))
    sheet = Image.new("RGB", (columns * cell_w + GAP, math.ceil(len(images) / columns) * cell_h
                              + GAP), (24, 24, 24))
    draw = ImageDraw.Draw(sheet)
    font = ImageFont.load_default()
    for index, (row, image) in enumerate(zip(rows, images, strict=True)):
        x, y = GAP + (index % columns) * cell_w, GAP + (index // columns) * cell_h
        sheet.paste(image, (x, y))
        draw.text((x + 2, y + image.height + 4), label(row), fill=(230, 230, 230), font=font)
        image.close()
    data = io.BytesIO()
    sheet.save(data, format="PNG")
    return data.getvalue()


def label(row: dict[str, Any]) -> str:
    measured = "" if row["chroma"] is None else f"  C* {row['chroma']:.1f}  L* {row['lightness']:.0f}"
    return f"{row['preset']} ({row['lighting']}){measured}"


def table(rows: list[dict[str, Any]], folder: str) -> str:
    """The Markdown table: one line per picture, linked."""
    lines = ["| preset | mesh | lighting | mean C\\*ab | mean L\\* | backdrop C\\*ab | picture |",
             "|---|---|---|---:|---:|---:|---|"]
    for row in rows:
        figures = " | ".join("–" if row[key] is None else f"{row[key]:.1f}"
                             for key in ("chroma", "lightness", "backdrop_chroma"))
        lines.append(f"| `{row['preset']}` | {row['mesh'] or '(its own)'} | {row['lighting']} | "
                     f"{figures} | [{row['image']}]({folder}/{row['image']}) |")
    return "\n".join(lines)


def sheets_section(sheets: list[str], folder: str) -> str:
    return "\n\n".join(f"![{name}]({folder}/{name})" for name in sheets)


def write_page(page: Path, rows: list[dict[str, Any]], sheets: list[str], folder: str) -> None:
    """``page`` with the table and sheets between the markers; the rest of it kept (a new
    page gets a heading and the markers)."""
    text = page.read_text() if page.exists() else PAGE_HEAD + BEGIN + "\n" + END + "\n"
    if BEGIN not in text or END not in text:
        text = text.rstrip("\n") + "\n\n" + BEGIN + "\n" + END + "\n"
    head, rest = text.split(BEGIN, 1)
    tail = rest.split(END, 1)[1]
    body = f"{sheets_section(sheets, folder)}\n\n{table(rows, folder)}"
    write_atomic(page, f"{head}{BEGIN}\n{body}\n{END}{tail}".encode())
