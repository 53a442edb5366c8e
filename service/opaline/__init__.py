"""Opaline: headless previews of iridescent materials (Kang, Lee, Cho 2014).

``from opaline import render`` gives the Python API (see docs/python.md); it is
imported on first use so that importing the package stays light.
"""

from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"
__all__ = ["__version__", "render", "render_array"]

if TYPE_CHECKING:  # type checkers see the real signatures; at run time they load lazily
    from opaline.local.api import render, render_array


def __getattr__(name: str) -> Any:
    if name in ("render", "render_array"):
        from opaline.local import api as api_python

        return getattr(api_python, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
