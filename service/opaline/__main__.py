"""``python -m opaline`` is the ``opaline`` command."""

from opaline.cli.main import command

raise SystemExit(command())
