"""`opaline gallery`: the pictures, their measured chroma, the contact sheets and the table."""

from __future__ import annotations

import io
import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from opaline.cli import gallery_report as report
from opaline.cli import main as cli
from opaline.cli.gallery_scenes import object_colour
from opaline.scene.environments import MESH_ENVIRONMENT

BUNNY = Path(__file__).parents[1] / "assets" / "bunny.ply"
RED, GREEN = (255, 0, 0), (0, 255, 0)
# C*ab of sRGB red and green (CIELAB, D65).
RED_CHROMA, GREEN_CHROMA = 104.58, 119.78


def png(rgba: np.ndarray) -> bytes:
    data = io.BytesIO()
    Image.fromarray(rgba.astype(np.uint8), "RGBA").save(data, format="PNG")
    return data.getvalue()


def square_on_backdrop(size: int = 16) -> tuple[bytes, bytes]:
    """A red square on green, and the mask a transparent render of it would give."""
    image = np.zeros((size, size, 4))
    image[..., :3], image[..., 3] = GREEN, 255
    image[4:12, 4:12, :3] = RED
    mask = np.zeros((size, size, 4))
    mask[4:12, 4:12] = (*RED, 255)
    return png(image), png(mask)


def test_chroma_is_measured_over_the_objects_pixels_and_the_backdrop_apart():
    measured = object_colour(*square_on_backdrop())
    assert measured["pixels"] == 64
    assert measured["chroma"] == pytest.approx(RED_CHROMA, abs=0.01)
    assert measured["lightness"] == pytest.approx(53.23, abs=0.01)
    assert measured["backdrop_chroma"] == pytest.approx(GREEN_CHROMA, abs=0.01)


def test_an_uncovered_image_has_no_object_figures():
    image, _ = square_on_backdrop()
    measured = object_colour(image, png(np.zeros((16, 16, 4))))
    assert measured["pixels"] == 0 and measured["chroma"] is None
    assert measured["backdrop_chroma"] is not None


def row(image: str, chroma: float | None) -> dict:
    return {"image": image, "sheet": "s", "preset": "sphere", "mesh": None,
            "lighting": "studio", "chroma": chroma, "lightness": 50.0, "pixels": 1,
            "backdrop_chroma": None}


def test_the_page_keeps_its_own_text_and_rewrites_the_table(tmp_path):
    page = tmp_path / "gallery.md"
    report.write_page(page, [row("a.png", 12.345)], ["sheet-s.png"], "gallery")
    first = page.read_text()
    assert first.startswith("# Gallery") and "| `sphere` | (its own) | studio | 12.3 | 50.0 | – |" \
        in first and "![sheet-s.png](gallery/sheet-s.png)" in first
    page.write_text(first.replace("# Gallery\n", "# Gallery\n\nWhat the pictures show.\n")
                    + "\nA closing note.\n")
    report.write_page(page, [row("b.png", None)], [], "gallery")
    second = page.read_text()
    assert "What the pictures show." in second and second.endswith("A closing note.\n")
    assert "a.png" not in second and "| – | 50.0 | – | [b.png](gallery/b.png) |" in second


@pytest.mark.gl
@pytest.mark.usefixtures("shared_renderer")
def test_gallery_renders_measures_and_sheets_a_subset(capsys, tmp_path):
    out = tmp_path / "gallery"
    code = cli.main(["gallery", "--out", str(out), "--size", "32", "--mdf-size", "16",
                     "--quality", "draft", "--presets", "sphere,soap-bubble",
                     "--mesh", str(BUNNY), "--mesh-presets", "oil-film"])
    assert code == 0, capsys.readouterr().err
    written = json.loads((out / "gallery.json").read_text())
    assert written["presets"] == ["preset-sphere.png", "preset-soap-bubble.png"]
    lighting = {r["image"]: r["lighting"] for r in written["measured"]}
    assert lighting == {"preset-sphere.png": "preset lights",
                        "preset-soap-bubble.png": "studio",  # the preset names it
                        "studio-sphere.png": "studio", "studio-soap-bubble.png": "studio",
                        "bunny-oil-film-studio.png": "studio",
                        "bunny-oil-film-default.png": MESH_ENVIRONMENT}
    for measured in written["measured"]:
        assert 0 < measured["pixels"] < 32 * 32, measured  # the object, not the frame
        assert 0.0 < measured["chroma"] < 150.0 and 0.0 < measured["lightness"] <= 100.0
        assert Image.open(out / measured["image"]).size == (32, 32)
    assert len(written["mdf"]) == 11
    assert written["sheets"] == ["sheet-presets-default.png", "sheet-presets-studio.png",
                                 "sheet-bunny-studio.png", "sheet-bunny-default.png"]
    assert Image.open(out / "sheet-bunny-studio.png").width == Image.open(
        out / "sheet-presets-studio.png").width // 2 + 2  # 1 picture against 2, gaps
    page = (tmp_path / "gallery.md").read_text()
    assert all(f"(gallery/{r['image']})" in page for r in written["measured"])
    # The README's pictures are what `opaline render` draws.
    code = cli.main(["render", "sphere", "--size", "32x32", "--quality", "draft",
                     "-o", str(tmp_path / "sphere.png")])
    assert code == 0 and (tmp_path / "sphere.png").read_bytes() == (
        out / "preset-sphere.png").read_bytes()
