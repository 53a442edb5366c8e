"""The ``opaline`` command: the parser, the global options and the one-line errors.

Sub-commands live beside it (render and mdf in ``render``, batch, gallery, serve,
schema); ``presets`` and ``info`` are small enough to stay here. Every failure a
user can cause or meet ends as one line on stderr, never a traceback: exit
status 2 for a usage error, 1 for a failure of the machine or the output, 130
for Ctrl-C, 141 when the reader of stdout went away (``| head``).
"""

from __future__ import annotations

import argparse
import gc
import json
import logging
import os
import signal
import sys
from pathlib import Path
from typing import Any

from opaline import __version__
from opaline.cli import batch, export, gallery, merge, render, schema, serve, turntable
from opaline.cli.args import CliError, add_common
from opaline.model.material_file import MaterialError
from opaline.model.meshes import MeshFileMissing
from opaline.model.params import RenderRequest
from opaline.model.presets import PresetError, UnknownPreset, all_presets
from opaline.model.request import CostError, resolve
from opaline.pipeline.limits import LimitError
from opaline.resources import PRESETS_ENV, presets_dir
from opaline.scene.environment_files import EnvironmentMapError
from opaline.scene.meshfile import MeshError
from opaline.settings import SettingsError

log = logging.getLogger("opaline.cli")
USAGE_ERRORS = (PresetError, UnknownPreset, CostError, MaterialError, MeshError,
                EnvironmentMapError, MeshFileMissing, SettingsError, LimitError)
# Commands that read presets take --presets-dir; `mdf --help` must not talk about presets.
USES_PRESETS = ("render", "presets", "batch", "gallery", "serve", "turntable", "export",
                "import")


def cmd_presets(args: argparse.Namespace) -> None:
    presets = all_presets()
    if args.json:
        print(json.dumps({n: p.model_dump(mode="json") for n, p in presets.items()}, indent=2))
        return
    for name, preset in presets.items():
        job = resolve(RenderRequest(preset=name), preset)
        m = job.material
        params = (
            f"mdf={m.mdf} mu_f={m.mu_f:g} alpha={m.alpha:g} beta={m.beta:g}"
            if m.mdf == "multipeak"
            else f"mdf={m.mdf} ex={m.ex:g} ey={m.ey:g}"
        )
        print(f"{name:<18} {preset.description}")
        print(f"{'':<18} {preset.figure}")
        print(
            f"{'':<18} defaults: {params} theta1={m.theta1:.4g} theta2={m.theta2:.4g} "
            f"kd={m.kd:g} ks={m.ks:g} f0={m.f0:g}"
        )


def cmd_info(args: argparse.Namespace) -> None:
    from opaline.gl.context import create_context

    gl = create_context(args.backend)
    try:
        info = gl.describe()
    finally:
        gl.release()
    for key, value in info.items():
        print(f"{key}: {value}")


def add_global(parser: argparse.ArgumentParser, presets: bool, top: bool = False) -> None:
    """-q/-v (and --presets-dir) before or after the sub-command: a sub-command's copy has no
    default, so it does not undo a value given before the sub-command."""
    default: dict[str, Any] = {} if top else {"default": argparse.SUPPRESS}
    loudness = parser.add_mutually_exclusive_group()
    loudness.add_argument("-q", "--quiet", action="store_true", **default,
                          help="no progress or information on stderr; errors only")
    loudness.add_argument("-v", "--verbose", action="store_true", **default,
                          help="log what is done (resolved job, tier, timings) to stderr")
    if presets:
        parser.add_argument("--presets-dir", metavar="DIR", **({"default": None} | default),
                            help=f"folder of scene presets (TOML) to use instead of the "
                                 f"built-in ones (default ${PRESETS_ENV})")


def make_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="opaline",
        description="Headless previews of iridescent materials (Kang, Lee, Cho 2014).",
    )
    parser.add_argument("--version", action="version", version=f"opaline {__version__}")
    add_global(parser, presets=True, top=True)
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    render.register(sub)

    presets = sub.add_parser("presets", help="list presets with their descriptions and defaults")
    presets.add_argument("--json", action="store_true", help="full preset data as JSON")
    presets.set_defaults(func=cmd_presets)

    info = sub.add_parser("info", help="report the GL backend and renderer Opaline gets")
    add_common(info)
    info.set_defaults(func=cmd_info)

    for module in (gallery, serve, batch, merge, schema, turntable, export):
        module.register(sub)
    for name, command in sub.choices.items():
        add_global(command, presets=name in USES_PRESETS)
    return parser


def use_presets_dir(folder: str | None) -> None:
    """--presets-dir: the same as $OPALINE_PRESETS_DIR, set before any preset is loaded.
    Either naming no folder is an error (the variable's was taken as a folder of no
    presets: `presets` listed none and `render` offered "choose one of " nothing)."""
    if folder is None:
        chosen = os.environ.get(PRESETS_ENV)
        if chosen and not Path(chosen).expanduser().is_dir():
            raise CliError(f"{PRESETS_ENV}={chosen}: no such folder")
        return
    if not Path(folder).expanduser().is_dir():
        raise CliError(f"--presets-dir {folder}: no such folder")
    os.environ[PRESETS_ENV] = folder  # read by resources.presets_dir, here and in workers
    all_presets.cache_clear()


def main(argv: list[str] | None = None) -> int:
    args = make_parser().parse_args(argv)
    logger = logging.getLogger("opaline")
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter(f"opaline {args.command}: %(message)s"))
    saved = logger.level, logger.propagate
    level = logging.ERROR if args.quiet else logging.INFO if args.verbose else logging.WARNING
    logger.setLevel(level)
    logger.propagate = args.command == "serve"  # serve logs through the root, beside uvicorn
    if not logger.propagate:
        logger.addHandler(handler)
    try:
        return run(args)
    finally:
        logger.removeHandler(handler)
        logger.setLevel(saved[0])
        logger.propagate = saved[1]


def command() -> int:
    """The ``opaline`` command of a process of its own (the console script, ``python -m
    opaline``): ``main``, then a quick way out. Python's exit runs full garbage collections
    over everything the command loaded (pydantic's models, NumPy ...): 30 ms of a 0.3 s
    ``opaline render``, more than the floor script's whole exit. Frozen, those objects are
    skipped; atexit handlers, the flush of stdout and stderr and reference-count clean-up
    still run (``main`` itself leaves the caller's collector alone, for tests and callers
    in a longer process)."""
    status = main()
    gc.freeze()
    return status


def run(args: argparse.Namespace) -> int:
    def fail(message: object, status: int) -> int:
        print(f"opaline {args.command}: error: {message}", file=sys.stderr)
        return status

    try:
        use_presets_dir(getattr(args, "presets_dir", None))
        if args.command in USES_PRESETS:
            log.info("presets from %s", presets_dir())
        args.func(args)
        sys.stdout.flush()  # a closed pipe shows here, inside the handler below
    except BrokenPipeError:
        # The reader went away (`| head`): as the Python docs advise, point stdout at
        # devnull so the flush at exit does not fail again, and exit as SIGPIPE would.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 128 + signal.SIGPIPE
    except CliError as exc:
        return fail(exc, exc.status)
    except USAGE_ERRORS as exc:
        return fail(exc, 2)
    except KeyboardInterrupt:
        print(f"opaline {args.command}: interrupted", file=sys.stderr)
        return 130
    except OSError as exc:  # a file or folder the command could not read or write
        where = exc.filename if exc.filename is not None else ""
        return fail(f"{where}: {exc.strerror}" if where and exc.strerror else exc, 1)
    except Exception as exc:  # context or shader failures: one line, non-zero
        # Imported here, not at the top: `opaline render` must not pay for pygltflib.
        from opaline.gl.context import ContextError
        from opaline.gl.shaders import ShaderError
        from opaline.output.gltf import GltfImportError

        if isinstance(exc, GltfImportError):
            return fail(exc, 2)
        if isinstance(exc, (ContextError, ShaderError)):
            return fail(exc, 1)
        raise
    return 0


if __name__ == "__main__":
    # Run the imported module's main, not this __main__ copy: sub-command modules raise
    # opaline.cli.args.CliError, which a second copy of the class would not catch.
    from opaline.cli.main import command as _command

    sys.exit(_command())
