"""A job's outcome that no client awaits any more is read, not logged as lost."""

from __future__ import annotations

import asyncio
import gc
from concurrent.futures import Future

from opaline.workers.errors import Cancelled
from opaline.workers.job import awaited


def test_an_outcome_no_one_awaits_is_not_logged_as_lost():
    """A client that left leaves its job's future to be failed later with Cancelled: asyncio
    logged "Future exception was never retrieved" for each (a review saw it in the log)."""

    async def leave_before_the_outcome() -> list[str]:
        reported: list[str] = []
        asyncio.get_running_loop().set_exception_handler(
            lambda loop, context: reported.append(context["message"]))
        source: Future[bytes] = Future()
        wrapped = awaited(source)
        source.set_exception(Cancelled("every client waiting for it left"))
        await asyncio.sleep(0.01)  # the outcome crosses to the loop
        assert wrapped.done()
        del wrapped, source
        gc.collect()
        return reported

    assert asyncio.run(leave_before_the_outcome()) == []
