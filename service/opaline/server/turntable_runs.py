"""Running a turntable on this replica: frames as ordinary render jobs, then a worker
encodes them; progress, result and failure go to the job's record
(``turntable_jobs``), so that any replica answers for it.

Turntables must not crowd out single renders, nor fail because single renders
filled the queue for a moment: all running turntables share one frame lane per
worker (so they add at most one frame per worker to the work ahead), and a frame
refused as Overloaded waits and is submitted again until the turntable's own
deadline (one render deadline per frame, plus one wait).
"""

from __future__ import annotations

import asyncio
from typing import Any

from pydantic import BaseModel

from opaline.errors import PublicError
from opaline.model.request import content_key
from opaline.model.turntable import TurntableRequest, check_turntable_cost, frame_jobs
from opaline.output.animation import encode_cost_s
from opaline.pipeline.prepare import prepare
from opaline.server.errors import UnknownTurntable
from opaline.server.queries import parse_body
from opaline.server.service import Service
from opaline.server.statestore import Record, StoreUnavailable
from opaline.server.turntable_jobs import CANCELLED, Job, Lost, StoredFailure, Turntables
from opaline.workers.animation_task import ENCODE_LABEL, AnimationTask
from opaline.workers.errors import DeadlineExceeded, Overloaded, TooSlow
from opaline.workers.tasks import ImageTask

Tasks = list[tuple[str, ImageTask]]


class TurntableStatus(BaseModel):
    id: str
    state: str  # running, done, failed, cancelled
    done: int
    frames: int
    error: str | None = None
    result: str


def status_of(value: dict[str, Any]) -> TurntableStatus:
    return TurntableStatus(id=value["id"], state=value["state"], done=value["done"],
                           frames=value["frames"], error=value["error"],
                           result=f"/v1/turntables/{value['id']}/result")


async def patiently(svc: Service, key: str, task: Any, deadline: float) -> bytes:
    """A render that waits out a full queue (Overloaded) until ``deadline`` (loop time)."""
    loop = asyncio.get_running_loop()
    while True:
        try:
            return await svc.pool.render(key, task, timeout=svc.wait_s)
        except Overloaded as exc:
            left = deadline - loop.time()
            if left <= 0:
                raise DeadlineExceeded(f"the queue stayed full until the turntable's "
                                       f"deadline ({exc})") from None
            await asyncio.sleep(min(max(exc.retry_after_s, 0.05), left))


async def run(svc: Service, found: Turntables, job: Job, tasks: Tasks, fps: int,
              shared: asyncio.Semaphore) -> None:
    frames: list[bytes | None] = [None] * len(tasks)
    loop = asyncio.get_running_loop()
    deadline = loop.time() + len(tasks) * svc.settings.deadline_s + svc.wait_s
    this = asyncio.current_task()
    assert this is not None
    beat = asyncio.create_task(found.heartbeat(job, this))

    async def one(index: int, key: str, task: ImageTask) -> None:
        async with shared:
            frames[index] = await patiently(svc, key, task, deadline)
        await found.update(job, done=sum(f is not None for f in frames))

    try:
        await asyncio.gather(*(one(i, key, task) for i, (key, task) in enumerate(tasks)))
        encode = AnimationTask(tuple(f for f in frames if f is not None), job.value["fmt"], fps)
        await found.finish(job, await patiently(svc, f"animation:{job.id}", encode, deadline))
    except Lost:
        pass  # another replica runs it now, or it was forgotten here
    except Exception as exc:  # kept: the result answers it as the public error it is
        await found.fail(job, exc)
    finally:
        beat.cancel()


def plan(svc: Service, raw: bytes) -> tuple[TurntableRequest, Tasks, str]:
    """A turntable's request, its frames' render tasks and its id (a content key)."""
    body = parse_body(raw, TurntableRequest)
    still = prepare(body.still(), svc.context)
    check_turntable_cost(still.job, body.frames, svc.settings.cost_budget)
    frames = [still.with_job(job) for job in frame_jobs(still.job, still.preset, body.frames)]
    tasks = [(frame.key, ImageTask(frame)) for frame in frames]
    predicted = svc.pool.cost.predict(*tasks[0][1].units())
    if predicted > svc.settings.deadline_s:  # every frame would be refused: say so now
        raise TooSlow(f"each frame is predicted to take {predicted:.1f} s, over the "
                      f"{svc.settings.deadline_s:g} s limit: lower width, height, samples or "
                      "wavelengths (or choose a lower quality)")
    job = still.job
    encoding = svc.pool.cost.predict(ENCODE_LABEL, 0.0, 0, encode_cost_s(
        body.frames, job.width, job.height, body.animation))
    if encoding > svc.settings.deadline_s:  # admission would refuse it after every frame
        raise TooSlow(f"encoding the {body.frames} frames as {body.animation} is predicted to "
                      f"take {encoding:.1f} s, over the {svc.settings.deadline_s:g} s limit: "
                      "lower frames, width or height (or choose gif, the fastest to encode)")
    key = content_key({"frames": [k for k, _ in tasks], "fmt": body.animation, "fps": body.fps})
    return body, tasks, key


async def start(svc: Service, found: Turntables, value: dict[str, Any], expect: int,
                shared: asyncio.Semaphore,
                planned: tuple[TurntableRequest, Tasks, str] | None = None) -> Record | None:
    """Run the job ``value`` here if its record is still at version ``expect``: its record
    as written, or None if another replica wrote first. ``planned``: its ``plan``, if made."""
    body, tasks, _ = planned or plan(svc, value["body"].encode())
    job = await found.claim(value, expect)
    if job is None:
        return None
    task = asyncio.create_task(run(svc, found, job, tasks, body.fps, shared))
    found.running[job.id] = (job, task)
    task.add_done_callback(lambda done: found.forget(job.id, done))
    return Record(job.version, job.value)


async def adopt(svc: Service, found: Turntables, record: Record,
                shared: asyncio.Semaphore) -> Record:
    """An orphaned job (its replica stopped renewing the lease) continued here, or failed
    with the reason it can no longer be rendered."""
    value = {**record.value, "done": 0}
    try:
        started = await start(svc, found, value, record.version, shared)
    except StoreUnavailable:
        raise
    except PublicError as exc:  # its mesh was evicted, the limits changed ...
        job = await found.claim(value, record.version)
        if job is not None:
            await found.fail(job, exc)
        started = None
    return started or await found.read(value["id"]) or record


def unknown_line(turntable_id: str) -> str:
    return (f"turntable {turntable_id!r} is not known here: start it with "
            "POST /v1/turntables (one is forgotten OPALINE_TURNTABLE_KEEP_S after its last "
            "change, its animation sooner past the kept animations' byte budget)")


async def current(svc: Service, found: Turntables, turntable_id: str,
                  shared: asyncio.Semaphore) -> dict[str, Any]:
    """The job's record as it stands, after taking it over if it was orphaned. A cancelled
    job is gone for reads (404 ``cancelled``): a successful DELETE is not followed by a 2xx
    GET."""
    record = await found.read(turntable_id)
    if record is None:
        raise UnknownTurntable(unknown_line(turntable_id))
    if record.value["state"] == "cancelled":
        raise StoredFailure(CANCELLED)  # not the record's: one written before 404 said 409
    if found.orphaned(record):
        record = await adopt(svc, found, record, shared)
    return record.value
