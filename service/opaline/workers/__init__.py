"""Render worker processes, shared by the HTTP service and ``opaline batch``.

Each worker is a spawned process with its own GL context (``child``); the
parent supervises them (``pool``): a bounded queue, admission against the
deadline (``admission``), a watchdog, recycling, and cancellation. Nothing in
the parent process touches GL.
"""
