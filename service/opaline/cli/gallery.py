"""``opaline gallery``: the README's pictures: every preset under its own lights and under
the studio, real meshes with a set of presets (``gallery_scenes``), each with its mean
chroma; contact sheets and the table (``gallery_report``); the paper's MDF figures."""

from __future__ import annotations

import argparse
import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any, get_args

from opaline.cli import gallery_report as report
from opaline.cli import gallery_scenes as scenes
from opaline.cli.args import add_common
from opaline.model.params import Material, Quality
from opaline.output.files import write_atomic

# The paper's MDF figures. Figs. 2, 6, 7 are single-channel (no rotation);
# Figs. 3 and 8 rotate G and B.
MDF_FIGURES: dict[str, dict[str, Any]] = {
    "fig2a-ashikhmin-ex100-ey10": {
        "mdf": "ashikhmin",
        "ex": 100,
        "ey": 10,
        "theta1": 0,
        "theta2": 0,
    },
    "fig2b-ashikhmin-ex10-ey100": {
        "mdf": "ashikhmin",
        "ex": 10,
        "ey": 100,
        "theta1": 0,
        "theta2": 0,
    },
    "fig3a-ashikhmin-rotated": {
        "mdf": "ashikhmin",
        "ex": 100,
        "ey": 10,
        "theta1": 0.2,
        "theta2": 0.4,
    },
    "fig3b-ashikhmin-rotated": {
        "mdf": "ashikhmin",
        "ex": 10,
        "ey": 100,
        "theta1": 0.2,
        "theta2": 0.4,
    },
    "fig6a-multipeak-mu2": {"mu_f": 2, "alpha": 1, "beta": 1, "theta1": 0, "theta2": 0},
    "fig6b-multipeak-mu5": {"mu_f": 5, "alpha": 1, "beta": 1, "theta1": 0, "theta2": 0},
    "fig6c-multipeak-mu10": {"mu_f": 10, "alpha": 1, "beta": 1, "theta1": 0, "theta2": 0},
    "fig7a-multipeak-mu2-a1-b0.1": {"mu_f": 2, "alpha": 1, "beta": 0.1, "theta1": 0, "theta2": 0},
    "fig7b-multipeak-mu5-a1-b0.1": {"mu_f": 5, "alpha": 1, "beta": 0.1, "theta1": 0, "theta2": 0},
    "fig7c-multipeak-mu10-a1-b0.1": {"mu_f": 10, "alpha": 1, "beta": 0.1, "theta1": 0, "theta2": 0},
    "fig8-multipeak-rotated": {"mu_f": 8.5, "alpha": 2, "beta": 1.2, "theta1": 0.1, "theta2": 0.2},
}


def build_gallery(
    out: Path,
    size: int = 256,
    mdf_size: int = 256,
    backend: str | None = None,
    quality: Quality = "standard",
    presets: Sequence[str] | None = None,
    meshes: Sequence[Path] | None = None,
    mesh_presets: Sequence[str] | None = None,
) -> dict[str, list[Any]]:
    """Every picture, gallery.json, and the table of ``out``'s page (docs/gallery.md for
    docs/gallery). None: every preset; the checkout's meshes; the mesh presets it has."""
    from opaline.local.pipeline import LocalRenderer
    from opaline.model.presets import all_presets

    chosen = list(all_presets()) if presets is None else list(presets)
    if meshes is None:
        meshes = [mesh for mesh in scenes.DEFAULT_MESHES if mesh.is_file()]
    if mesh_presets is None:
        mesh_presets = [name for name in scenes.MESH_PRESETS if name in all_presets()]
    shots = scenes.preset_shots(chosen) + scenes.mesh_shots(meshes, mesh_presets)
    out.mkdir(parents=True, exist_ok=True)
    written: dict[str, list[Any]] = {"presets": [f"preset-{name}.png" for name in chosen],
                                     "mdf": [], "measured": [], "sheets": []}
    with LocalRenderer(backend) as renderer:
        for shot in shots:
            written["measured"].append(scenes.render_shot(renderer, shot, out, size, quality))
        for name, fields in MDF_FIGURES.items():
            path = out / f"mdf-{name}.png"
            write_atomic(path, renderer.mdf_bytes(Material(**fields), mdf_size))
            written["mdf"].append(path.name)
    written["sheets"] = report.write_sheets(out, written["measured"])
    write_atomic(out / "gallery.json", json.dumps(written, indent=2).encode())
    report.write_page(out.parent / f"{out.name}.md", written["measured"], written["sheets"],
                      out.name)
    return written


def names(value: str) -> list[str]:
    return [name.strip() for name in value.split(",") if name.strip()]


def cmd_gallery(args: argparse.Namespace) -> None:
    meshes = None if args.mesh is None else [Path(mesh) for mesh in args.mesh]
    written = build_gallery(Path(args.out), args.size, args.mdf_size, args.backend, args.quality,
                            args.presets, meshes, args.mesh_presets)
    print(f"wrote {len(written['measured'])} measured images, {len(written['mdf'])} MDF plots "
          f"and {len(written['sheets'])} contact sheets to {args.out}")


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = sub.add_parser(
        "gallery", help="render every preset (own lights, studio), real meshes with a set of "
        "presets, and the paper's MDF figures, with each picture's chroma (README pictures)"
    )
    parser.add_argument(
        "--out", default="docs/gallery",
        help="output folder (default docs/gallery); the table goes to OUT.md beside it"
    )
    parser.add_argument("--size", type=int, default=256, help="preset image size (default 256)")
    parser.add_argument("--mdf-size", type=int, default=256, help="MDF plot size (default 256)")
    parser.add_argument("--quality", default="standard", choices=get_args(Quality))
    parser.add_argument("--presets", type=names, default=None, metavar="LIST",
                        help="comma-separated presets to render (default: every preset)")
    parser.add_argument("--mesh", action="append", default=None, metavar="PATH",
                        help="a mesh file to render the mesh presets on; repeat for more "
                        "(default: the checkout's tests/assets bunny.ply, spot.obj, teapot.obj)")
    parser.add_argument("--mesh-presets", type=names, default=None, metavar="LIST",
                        help="comma-separated presets shown on each mesh, '' for none "
                        f"(default: {','.join(scenes.MESH_PRESETS)})")
    add_common(parser)
    parser.set_defaults(func=cmd_gallery)
