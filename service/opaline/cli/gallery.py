"""``opaline gallery``: the README's pictures, one image per preset and the MDF figures."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any, get_args

from opaline.cli.args import add_common
from opaline.model.params import Material, Quality, RenderRequest
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
) -> dict[str, list[str]]:
    from opaline.local.pipeline import LocalRenderer
    from opaline.model.presets import all_presets

    out.mkdir(parents=True, exist_ok=True)
    written: dict[str, list[str]] = {"presets": [], "mdf": []}
    with LocalRenderer(backend) as renderer:
        for name in all_presets():
            request = RenderRequest(preset=name, width=size, height=size, quality=quality)
            path = out / f"preset-{name}.png"
            write_atomic(path, renderer.render_bytes(request))
            written["presets"].append(path.name)
        for name, fields in MDF_FIGURES.items():
            path = out / f"mdf-{name}.png"
            write_atomic(path, renderer.mdf_bytes(Material(**fields), mdf_size))
            written["mdf"].append(path.name)
    write_atomic(out / "gallery.json", json.dumps(written, indent=2).encode())
    return written


def cmd_gallery(args: argparse.Namespace) -> None:
    written = build_gallery(Path(args.out), args.size, args.mdf_size, args.backend, args.quality)
    print(
        f"wrote {len(written['presets'])} preset images and {len(written['mdf'])} MDF plots to {args.out}"
    )


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = sub.add_parser(
        "gallery", help="render every preset and the paper's MDF figures (README pictures)"
    )
    parser.add_argument(
        "--out", default="docs/gallery", help="output folder (default docs/gallery)"
    )
    parser.add_argument("--size", type=int, default=256, help="preset image size (default 256)")
    parser.add_argument("--mdf-size", type=int, default=256, help="MDF plot size (default 256)")
    parser.add_argument("--quality", default="standard", choices=get_args(Quality))
    add_common(parser)
    parser.set_defaults(func=cmd_gallery)
