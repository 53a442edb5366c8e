"""Connection hygiene under uvicorn: read timeouts, per-address caps, stalled readers.

uvicorn sets no header or body read timeout, so half-sent requests stayed open
(1032 of them from one client made every other client get its text/plain 503).
``guarded_protocol`` returns uvicorn's h11 protocol with:

- a header timeout: a connection whose request head is not complete this long
  after it opened (or after its previous answer) is closed;
- a body timeout: a request whose body is not complete this long after its
  head, plus a second for every ``min_body_rate`` bytes that did arrive, answers
  408 and is closed (a slow upload that keeps coming is not cut off; one that
  trickles in is);
- a write timeout: a client that takes nothing of an answer for this long is
  dropped (a chunked answer, ``opaline.server.streaming``, holds about one
  chunk for it meanwhile);
- a cap on open connections per client address and in all, answered at once
  with a JSON 503 and Retry-After, then closed.

Passed to uvicorn as ``http=``; ``opaline serve`` does so. Each refusal or
timeout is counted in ``STATS`` (exported on /metrics).
"""

from __future__ import annotations

import asyncio
import json
from collections import Counter

import h11
from h11._connection import DEFAULT_MAX_INCOMPLETE_EVENT_SIZE
from uvicorn.protocols.http.h11_impl import H11Protocol

from opaline.settings import Settings

# The request head h11 buffers at most (uvicorn leaves it at h11's default): past it, 431.
HEAD_LIMIT = DEFAULT_MAX_INCOMPLETE_EVENT_SIZE
# Refusals and timeouts since start, by kind: read by opaline.server.metrics.
STATS: Counter[str] = Counter()


def raw_problem(status: int, phrase: str, reason: str, line: str, retry_after: int = 0) -> bytes:
    """A whole HTTP/1.1 answer in the service's error shape, for the connection layer."""
    body = json.dumps({"error": reason, "detail": [line]}).encode()
    retry = f"Retry-After: {retry_after}\r\n" if retry_after else ""
    return (f"HTTP/1.1 {status} {phrase}\r\nContent-Type: application/json\r\n"
            f"Content-Length: {len(body)}\r\n{retry}Connection: close\r\n\r\n").encode() + body


def guarded_protocol(settings: Settings) -> type[H11Protocol]:
    per_client: Counter[str] = Counter()

    class Guarded(H11Protocol):
        _timer: asyncio.TimerHandle | None
        _write_timer: asyncio.TimerHandle | None

        # uvicorn's H11Protocol narrows asyncio's BaseTransport to Transport here, with
        # the same ignore in its own source: an override of it inherits the mismatch.
        def connection_made(self, transport: asyncio.Transport) -> None:  # type: ignore[override]
            super().connection_made(transport)
            self._timer = self._write_timer = None
            self._body_started, self._body_bytes = 0.0, 0
            self._address = self.client[0] if self.client else "unknown"
            per_client[self._address] += 1
            if len(self.connections) > settings.max_connections:
                self._refuse("connections", "the service has too many open connections")
            elif per_client[self._address] > settings.max_connections_per_client:
                self._refuse("per_client", "too many open connections from this address")
            else:
                self._arm(settings.header_timeout_s)

        def _refuse(self, kind: str, line: str) -> None:
            STATS["refused_" + kind] += 1
            self.transport.write(raw_problem(503, "Service Unavailable", "overloaded",
                                             f"{line}; retry later", settings.retry_after_s))
            self.transport.close()

        def _arm(self, delay: float) -> None:
            if self._timer is not None:
                self._timer.cancel()
            self._timer = self.loop.call_later(delay, self._read_timed_out)

        def _read_timed_out(self) -> None:
            self._timer = None
            if self.transport.is_closing():
                return
            state = self.conn.their_state
            if state is h11.SEND_BODY and not (self.cycle and self.cycle.response_started):
                earned = self._body_started + settings.body_timeout_s + (
                    self._body_bytes / settings.min_body_rate)
                if earned > self.loop.time():  # what arrived bought it more time
                    self._arm(earned - self.loop.time())
                    return
                STATS["body_timeouts"] += 1
                self.transport.write(raw_problem(408, "Request Timeout", "timeout",
                                                 "the request body did not arrive in time"))
                self.transport.close()
            elif state is h11.IDLE and (self.cycle is None or self.cycle.response_complete):
                STATS["header_timeouts"] += 1
                self.transport.close()

        def send_400_response(self, msg: str) -> None:
            """An unparsable request line or header: uvicorn's text/plain 400, in our shape;
            431 where the head outgrew h11's buffer (its error, not passed on, hints 431)."""
            STATS["malformed"] += 1
            if len(self.conn.trailing_data[0]) > HEAD_LIMIT:
                answer = raw_problem(431, "Request Header Fields Too Large", "malformed",
                                     f"the request line and headers are over {HEAD_LIMIT} "
                                     "bytes: send the parameters in a POST body")
            else:
                answer = raw_problem(400, "Bad Request", "malformed",
                                     "the request is not valid HTTP/1.1")
            self.transport.write(answer)
            self.transport.close()

        def data_received(self, data: bytes) -> None:
            if self.transport.is_closing():  # refused or timed out: read nothing more
                return
            before = self.conn.their_state
            super().data_received(data)
            after = self.conn.their_state
            if after is h11.SEND_BODY and before is not h11.SEND_BODY:
                self._body_started, self._body_bytes = self.loop.time(), 0
                self._arm(settings.body_timeout_s)
            elif after is h11.SEND_BODY:
                self._body_bytes += len(data)
            elif after is h11.DONE and self._timer is not None:
                self._timer.cancel()
                self._timer = None

        def on_response_complete(self) -> None:
            super().on_response_complete()
            if not self.transport.is_closing():  # the next request's head has its own time
                self._arm(settings.header_timeout_s)

        def pause_writing(self) -> None:
            super().pause_writing()
            self._write_timer = self.loop.call_later(settings.write_timeout_s, self._stalled)

        def resume_writing(self) -> None:
            super().resume_writing()
            if self._write_timer is not None:
                self._write_timer.cancel()
                self._write_timer = None

        def _stalled(self) -> None:
            STATS["write_timeouts"] += 1
            self.transport.abort()

        def connection_lost(self, exc: Exception | None) -> None:
            for timer in (self._timer, self._write_timer):
                if timer is not None:
                    timer.cancel()
            per_client[self._address] -= 1
            if per_client[self._address] <= 0:
                del per_client[self._address]
            super().connection_lost(exc)

    return Guarded
