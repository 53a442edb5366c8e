"""``python -m service`` is the ``opaline`` command."""

from .cli import main

raise SystemExit(main())
