"""Rendering in this process: ``LocalRenderer`` and ``from opaline import render``."""
