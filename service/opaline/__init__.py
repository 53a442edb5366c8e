"""Opaline: headless previews of iridescent materials (Kang, Lee, Cho 2014).

``from opaline import render`` gives the Python API (see docs/python.md); it is
imported on first use so that importing the package stays light.
"""

from typing import TYPE_CHECKING, Any

__version__ = "0.2.0"
__all__ = ["__version__", "export_material", "render", "render_array", "render_turntable"]

if TYPE_CHECKING:  # type checkers see the real signatures; at run time they load lazily
    from opaline.local.api import render, render_array
    from opaline.local.export import export_material
    from opaline.local.turntable import render_turntable

LAZY = {"render": "api", "render_array": "api", "render_turntable": "turntable",
        "export_material": "export"}


def __getattr__(name: str) -> Any:
    if name in LAZY:
        from importlib import import_module

        return getattr(import_module(f"opaline.local.{LAZY[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
