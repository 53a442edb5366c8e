"""``python -m opaline`` is the ``opaline`` command."""

from opaline.cli.main import main

raise SystemExit(main())
