"""``opaline serve``: the HTTP service under uvicorn, on the guarded h11 protocol."""

from __future__ import annotations

import argparse

from opaline.cli.args import add_common


def cmd_serve(args: argparse.Namespace) -> None:
    import logging

    import uvicorn
    from pydantic import ValidationError

    from opaline.cli.args import CliError
    from opaline.model.params import describe_errors
    from opaline.server.api import create_app
    from opaline.server.connections import guarded_protocol
    from opaline.settings import Settings

    overrides = {"host": args.host, "port": args.port, "workers": args.workers,
                 "gl_backend": args.backend, "queue_size": args.queue_size}
    try:
        settings = Settings(**{k: v for k, v in overrides.items() if v is not None})
    except ValidationError as exc:
        raise CliError("; ".join(describe_errors(exc, Settings))) from None
    # uvicorn configures only its own loggers; the service's (worker start-up, render
    # failures with their tracebacks and shader logs) go to stderr beside them.
    logging.basicConfig(level=args.log_level.upper(),
                        format="%(levelname)s:     %(name)s: %(message)s")
    # The guarded protocol caps connections (in all and per address) and times out slow
    # reads and writes; uvicorn's own limit would answer a bare text/plain 503.
    uvicorn.run(create_app(settings), host=settings.host, port=settings.port,
                log_level=args.log_level, http=guarded_protocol(settings),
                limit_concurrency=None, timeout_graceful_shutdown=10)


def register(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    serve = sub.add_parser(
        "serve", help="run the HTTP service",
        description="Serve the HTTP API (docs at /docs). Every setting can also come from an "
                    "OPALINE_* environment variable, e.g. OPALINE_QUEUE_SIZE=64.")
    serve.add_argument("--host", help="address to bind (default $OPALINE_HOST or 127.0.0.1)")
    serve.add_argument("--port", type=int, help="port to bind (default $OPALINE_PORT or 8000)")
    serve.add_argument("--workers", type=int,
                       help="render worker processes, one GL context each (default 1)")
    serve.add_argument("--queue-size", type=int, help="jobs that may wait before 503 (default 32)")
    add_common(serve)
    serve.add_argument("--log-level", default="info",
                       choices=["critical", "error", "warning", "info", "debug"])
    serve.set_defaults(func=cmd_serve)
