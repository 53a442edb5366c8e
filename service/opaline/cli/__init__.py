"""The ``opaline`` command line: one module per sub-command family."""
