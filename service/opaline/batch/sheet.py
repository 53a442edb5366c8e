"""``opaline batch --sheet``: a contact sheet of the outputs, DIR/index.html and DIR/sheet.png.

The page shows every output with its name and lists the failures with their
reasons; the PNG is a grid of thumbnails (THUMB pixels on the longer side),
each named underneath, with the failures as red cells.
"""

from __future__ import annotations

import io
import math
from html import escape
from pathlib import Path
from typing import TYPE_CHECKING, Any
from urllib.parse import quote

from opaline.output.files import write_atomic

if TYPE_CHECKING:
    from opaline.batch.plan import Task

THUMB = 128
LABEL = 18


def write_contact_sheet(out: Path, tasks: list[Task]) -> None:
    write_index(out, tasks)
    write_sheet(out, tasks)


# DIR/sheet.png

def thumbnail(path: Path) -> Any:
    """An RGB thumbnail of a PNG or a linear .npy output, THUMB pixels on its longer side."""
    import numpy as np
    from PIL import Image

    if path.suffix == ".npy":
        from opaline.model.reference import srgb_encode

        linear = np.load(path)
        rgb = srgb_encode(np.clip(linear[..., :3], 0.0, 1.0))
        image = Image.fromarray(np.rint(rgb * 255).astype(np.uint8), "RGB")
    else:
        with Image.open(path) as opened:
            image = opened.convert("RGBA")
        backdrop = Image.new("RGBA", image.size, (40, 40, 40, 255))
        image = Image.alpha_composite(backdrop, image).convert("RGB")
    scale = THUMB / max(image.size)
    size = (max(1, round(image.width * scale)), max(1, round(image.height * scale)))
    return image.resize(size, Image.Resampling.LANCZOS)


def write_sheet(out: Path, tasks: list[Task]) -> None:
    """A grid of every thumbnail with its name drawn under it; failures as red cells."""
    from PIL import Image, ImageDraw, ImageFont

    shown = [t for t in tasks if t.written or t.status == "failed"]
    columns = max(1, min(8, math.ceil(math.sqrt(len(shown) or 1))))
    rows = max(1, math.ceil(len(shown) / columns))
    cell_w, cell_h = THUMB + 8, THUMB + LABEL + 8
    sheet = Image.new("RGB", (columns * cell_w, rows * cell_h), (24, 24, 24))
    draw = ImageDraw.Draw(sheet)
    font = ImageFont.load_default()
    for index, task in enumerate(shown):
        x, y = (index % columns) * cell_w + 4, (index // columns) * cell_h + 4
        _draw_cell(sheet, draw, font, task, x, y)
    data = io.BytesIO()
    sheet.save(data, format="PNG")
    write_atomic(out / "sheet.png", data.getvalue())


def _draw_cell(sheet: Any, draw: Any, font: Any, task: Task, x: int, y: int) -> None:
    """One task's thumbnail (or red 'failed' square) at (x, y), its name under it."""
    if task.written and task.output is not None:
        thumb = thumbnail(task.output)
        sheet.paste(thumb, (x + (THUMB - thumb.width) // 2, y + (THUMB - thumb.height) // 2))
    else:
        draw.rectangle((x, y, x + THUMB - 1, y + THUMB - 1), fill=(110, 20, 20))
        draw.text((x + 6, y + 6), "failed", fill=(255, 220, 220), font=font)
    draw.text((x, y + THUMB + 3), _fit(draw, task.item.name, font), fill=(230, 230, 230),
              font=font)


def _fit(draw: Any, text: str, font: Any) -> str:
    if draw.textlength(text, font=font) <= THUMB:
        return text
    while text and draw.textlength(text + "…", font=font) > THUMB:
        text = text[1:]
    return "…" + text


# DIR/index.html

def write_index(out: Path, tasks: list[Task]) -> None:
    """An HTML page of the thumbnails with their names, and the failures with their reasons."""
    figures, failures = [], []
    for task in tasks:
        name = escape(task.item.name)
        if task.written and task.output is not None:
            figures.append(_figure(out, task.output, name))
        elif task.status == "failed":
            failures.append(f"<li><b>{name}</b>: {escape(task.error or task.status)}</li>")
    failed = (f"<h2>Failed ({len(failures)})</h2><ul>{''.join(failures)}</ul>"
              if failures else "")
    page = INDEX_TEMPLATE.format(count=len(figures), figures="\n".join(figures), failed=failed)
    write_atomic(out / "index.html", page.encode())


def _figure(out: Path, output: Path, name: str) -> str:
    """A PNG as an image, anything else (.npy) as a link, captioned with the escaped ``name``."""
    href = quote(output.relative_to(out).as_posix())
    body = (f'<img src="{href}" alt="{name}" loading="lazy">' if output.suffix == ".png"
            else f'<a href="{href}">{escape(output.name)}</a>')
    return f"<figure>{body}<figcaption>{name}</figcaption></figure>"


INDEX_TEMPLATE = """<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>Opaline thumbnails</title>
<style>
body {{ font: 14px system-ui, sans-serif; background: #181818; color: #eee; margin: 2em; }}
main {{ display: grid; grid-template-columns: repeat(auto-fill, minmax(150px, 1fr)); gap: 1em; }}
figure {{ margin: 0; text-align: center; }}
img {{ max-width: 128px; max-height: 128px; image-rendering: auto; }}
figcaption {{ word-break: break-all; }} li {{ margin: .3em 0; }}
</style></head><body>
<h1>Opaline thumbnails ({count})</h1>
<main>
{figures}
</main>
{failed}
</body></html>
"""
