"""Admission's predictor (issue 24): every cost driver counted, so what it admits ends before
the watchdog. Pure: a cost model calibrated from timings measured on this project's 2-core
llvmpipe machine, against renders timed there (the figures below, best of three)."""

from __future__ import annotations

import json
import os

import pytest

from mesh_helpers import mesh_bytes
from opaline.local.context import local_context
from opaline.model.params import RenderRequest
from opaline.model.presets import get_preset
from opaline.pipeline.prepare import prepare
from opaline.workers import pace
from opaline.workers.admission import SAFETY, CostModel, TooSlow, admit
from opaline.workers.calibration import (
    LABELS_PER_CALIBRATION,
    CalibrateTask,
    calibrated_labels,
    calibration_tasks,
)
from opaline.workers.tasks import ImageTask

# CalibrateTask's answer as a worker gave it for 'sphere' (192², 2 samples; 0 and 16
# wavelengths) and the tiny render's overhead.
CALIBRATION = {"overhead_s": 0.002, "units": 192 * 192 * 2, "wavelengths": 16,
               "timings": {"sphere": [0.009, 0.033]}}
# (request fields on 'sphere' at 192², 2 samples) → seconds measured.
MEASURED = [
    ({"iridescence": "thin-film", "wavelengths": 0}, 0.016),
    ({"iridescence": "grating", "grating_orders": 8, "wavelengths": 0}, 0.080),
    ({"wavelengths": 128}, 0.247),
    ({"iridescence": "thin-film", "wavelengths": 128}, 0.112),
    ({"iridescence": "grating", "grating_orders": 1, "wavelengths": 128}, 0.418),
    ({"iridescence": "grating", "grating_orders": 3, "wavelengths": 128}, 1.198),
    ({"iridescence": "grating", "grating_orders": 8, "wavelengths": 16}, 0.331),
    ({"iridescence": "grating", "grating_orders": 8, "wavelengths": 128}, 1.807),
]
DEADLINE_S = 10.0


def model() -> CostModel:
    found = CostModel()
    found.calibrate(json.dumps(CALIBRATION).encode())
    return found


def predicted(fields: dict, mesh: str | None = None) -> float:
    base = {"width": 192, "height": 192, "samples": 2} if mesh is None else {}
    request = RenderRequest(preset="sphere", mesh=mesh, **{**base, **fields})
    return model().predict(*ImageTask(prepare(request, local_context(None))).units())


def test_predictions_follow_load_that_came_after_the_calibration():
    """Renders running twice as long as the calibration predicts (another process on the
    cores) double the predictions within a few renders; when they run as predicted again
    the predictions return to the calibration's, never below it. Small renders barely
    move them. (A review saw a render predicted at 9.9 s take 15.2 s under such load:
    admitted, and late.)"""
    found = model()
    task = ImageTask(prepare(RenderRequest(preset="sphere", width=1024, height=1024,
                                           samples=16), local_context(None)))
    idle = found.predict_task(task)
    estimate = idle / SAFETY
    assert estimate > pace.WINDOW_S  # a long render: each moves the average a quarter
    for _ in range(12):
        found.observe(task, found.predict_task(task), 2.0 * estimate)
    assert 1.9 * idle < found.predict_task(task) <= 2.0 * idle
    for _ in range(30):
        found.observe(task, found.predict_task(task), 0.5 * estimate)
    assert found.predict_task(task) == idle
    small = ImageTask(prepare(RenderRequest(preset="sphere", width=64, height=64),
                              local_context(None)))
    found.warmed(small)  # compiled: its prediction is the render alone, a few ms
    for _ in range(12):
        found.observe(small, found.predict_task(small), 3.0 * found.predict_task(small) / SAFETY)
    assert found.predict_task(task) < 1.1 * idle
    uncalibrated = CostModel()
    for _ in range(12):
        uncalibrated.observe(task, uncalibrated.predict_task(task), 100.0)
    assert uncalibrated.pace.factor() == 1.0


@pytest.mark.parametrize("fields,seconds", MEASURED)
def test_never_under_what_was_measured(fields, seconds):
    """Before, every one of these was predicted from the rotations' timing: the 8-order
    grating at 128 wavelengths at 0.30 s, a sixth of its 1.81 s."""
    found = predicted(fields)
    assert seconds <= found <= 5 * seconds, (fields, found)


def test_the_issues_grating_and_mesh_are_refused_at_once(tmp_path):
    """8 orders, 128 wavelengths, a 2M-triangle mesh (a 42 MB file): predicted past the
    deadline, so refused before a worker starts what the watchdog would kill."""
    path = tmp_path / "big.glb"
    with open(path, "wb") as stream:  # sparse: only its size is read by admission
        stream.write(b"glTF")
        os.truncate(stream.fileno(), 42 << 20)
    fields = {"iridescence": "grating", "grating_orders": 8, "wavelengths": 128,
              "width": 512, "height": 512, "samples": 4}
    found = predicted(fields, mesh=str(path))
    assert isinstance(admit(found, 1, [], [], 32, DEADLINE_S), TooSlow), found
    # A 27 MB, 1.3M-triangle GLB drew its first 256² draft in 2.72 s (parsed), then 0.26 s.
    path.write_bytes(b"")
    with open(path, "wb") as stream:
        stream.write(b"glTF")
        os.truncate(stream.fileno(), 27 << 20)
    first = predicted({"width": 256, "height": 256, "quality": "draft"}, mesh=str(path))
    assert 2.72 <= first < DEADLINE_S


def test_a_variant_no_worker_rendered_yet_pays_its_compile():
    found = model()
    found.calibrate(json.dumps({**CALIBRATION, "cold_s": {"sphere": 0.2}}).encode())
    task = ImageTask(prepare(RenderRequest(preset="sphere", width=64, height=64),
                             local_context(None)))
    warm = found.predict(*task.units())
    assert found.predict_task(task) == pytest.approx(warm + 1.5 * 0.2)
    found.warmed(task)
    assert found.predict_task(task) == pytest.approx(warm)
    other = ImageTask(prepare(RenderRequest(preset="sphere", width=64, height=64,
                                            wavelengths=8), local_context(None)))
    assert found.predict_task(other) > found.predict(*other.units())  # another program


def test_the_calibration_is_jobs_of_a_few_labels_each_covering_every_label_once():
    """The calibration was one job over every label: 33 s on OSMesa with an empty shader
    cache, past the 30 s render limit on a slower machine, where the watchdog killed it and
    the service never calibrated (CI, 2026-12-04). Each job now times a few labels."""
    tasks = calibration_tasks()
    timed = [label for task in tasks for label, _, _ in task.labels()]
    assert sorted(timed) == sorted(label for label, _, _ in calibrated_labels())
    assert all(1 <= len(task.labels()) <= LABELS_PER_CALIBRATION for task in tasks)
    assert len(tasks) > 1 and {task.parts for task in tasks} == {len(tasks)}
    whole = CalibrateTask().units()[1]
    assert sum(task.units()[1] for task in tasks) == pytest.approx(whole)


def test_the_cost_model_is_calibrated_once_every_part_is_in():
    """A part's timings count at once; until the last part is in, a label no part timed yet
    is priced by the built-in guess, not by the cheap presets timed so far."""
    found = CostModel()
    guess = found.predict("morpho", 1e5, 0)
    found.calibrate(json.dumps({**CALIBRATION, "part": 0, "parts": 2,
                                "cold_s": {"sphere": 0.001}}).encode())
    assert not found.calibrated
    morpho = ImageTask(prepare(CalibrateTask._request(get_preset("morpho"), 0),
                               local_context(None)))
    assert found.predict_task(morpho) >= found.predict(*morpho.units()) + 1.5 * 0.1
    assert found.predict("morpho", 1e5, 0) == pytest.approx(guess, rel=0.2)
    sphere = found.predict("sphere", 1e5, 0)
    assert sphere < guess / 2
    found.calibrate(json.dumps({**CALIBRATION, "part": 1, "parts": 2, "overhead_s": 0.001,
                                "timings": {"morpho": [0.2, 0.6]}}).encode())
    assert found.calibrated and set(found.labels) == {"sphere", "morpho"}
    assert found.overhead_s == 0.002  # the largest of the parts'
    assert found.predict("sphere", 1e5, 0) == pytest.approx(sphere)
    assert found.predict("tempered-steel", 1e5, 0) == found.predict("morpho", 1e5, 0)


def _calibration_task(preset: str, wavelengths: int = 0,
                      environment: str | None = None) -> ImageTask:
    request = CalibrateTask._request(get_preset(preset), wavelengths, environment)
    return ImageTask(prepare(request, local_context(None)))


def test_a_users_mesh_is_priced_by_the_preset_it_names(tmp_path):
    """A mesh's scene is named by its file's digest, which no calibration covers: it was
    priced as the slowest preset (morpho, 10× the sphere), so the sky-lit default preview of a
    small upload was predicted at 13 s on a loaded machine and refused (CI, 2026-12-03)."""
    found = model()
    found.calibrate(json.dumps({**CALIBRATION, "timings": {
        "sphere": [0.009, 0.033], "morpho": [0.2, 0.6]}}).encode())
    path = tmp_path / "torus.glb"
    path.write_bytes(mesh_bytes("glb"))
    common = {"preset": "sphere", "width": 256, "height": 256, "environment": "none"}
    plain = ImageTask(prepare(RenderRequest(**common), local_context(None)))
    mesh = ImageTask(prepare(RenderRequest(**common, mesh=str(path)), local_context(None)))
    assert mesh.label == "sphere"  # also the metrics' label: uploads cannot grow them
    label, units, wavelengths, draw_s, load, read_s = mesh.units()
    assert draw_s > 0.0 and read_s > 0.0
    assert found.predict(*mesh.units()) == pytest.approx(
        found.predict(*plain.units()) + 1.5 * draw_s + read_s)


@pytest.mark.parametrize("fields", [{"width": 16, "height": 16, "quality": "draft"},
                                    {"width": 256, "height": 256, "quality": "draft"}])
def test_a_scan_at_the_triangle_limit_is_admitted(tmp_path, fields):
    """A review's 1,996,002-triangle binary PLY (38 MB, under the 2M limit) was refused at
    every size under the default 10 s deadline, predicted at 10.3 s at 16²: its read, at
    the slowest format's rate, took the safety factor too. Its first render took 5.4 s
    (read), later ones 0.23-0.43 s. Predicted now at no less than that first render, with
    room under the deadline for a first compile (up to 0.9 s, times the safety factor)
    and some load (the pace), which took the review's prediction over it."""
    path = tmp_path / "scan.ply"
    with open(path, "wb") as stream:  # sparse: only its size is read by admission
        stream.write(b"ply\n")
        os.truncate(stream.fileno(), 38 << 20)
    found = predicted(fields, mesh=str(path))
    assert 5.4 <= found <= 0.75 * DEADLINE_S, found


def test_a_mesh_read_taking_what_was_predicted_leaves_the_pace_alone(tmp_path):
    """The read is predicted without the safety factor; the pace took a render's model time
    as prediction / safety, so a scan read in exactly its predicted seconds counted as
    slower than predicted and raised every prediction after it."""
    path = tmp_path / "scan.ply"
    with open(path, "wb") as stream:
        stream.write(b"ply\n")
        os.truncate(stream.fileno(), 38 << 20)
    task = ImageTask(prepare(RenderRequest(preset="sphere", mesh=str(path), width=64,
                                           height=64), local_context(None)))
    found = model()
    predicted = found.predict(*task.units())
    label, units, wavelengths, draw_s, load, read_s = task.units()
    assert read_s > 5.0
    as_modelled = (predicted - read_s) / SAFETY + read_s  # the read and the shading's fit
    for _ in range(12):
        found.observe(task, predicted, as_modelled)
    assert found.pace.factor() == 1.0


def test_a_refusal_names_the_fields_that_made_it_slow(tmp_path):
    """The too_slow 422 said to lower width, height, samples or wavelengths, with no field,
    where the request had set environment_samples=4096 (the tier's own is 4); and a mesh
    file that is most of the time is named too."""
    heavy = ImageTask(prepare(RenderRequest(preset="soap-bubble", environment_samples=4096,
                                            width=256, height=256), local_context(None)))
    refusal = admit(model().predict(*heavy.units()), 1, [], [], 32, DEADLINE_S, "", heavy)
    assert isinstance(refusal, TooSlow)
    assert "lower environment_samples=4096, width=256, height=256" in str(refusal)
    assert [p["field"] for p in refusal.field_problems()] == [
        "environment_samples", "width", "height"]
    path = tmp_path / "big.glb"
    with open(path, "wb") as stream:
        stream.write(b"glTF")
        os.truncate(stream.fileno(), 62 << 20)
    scan = ImageTask(prepare(RenderRequest(preset="sphere", mesh=str(path)),
                             local_context(None)))
    refusal = admit(model().predict(*scan.units()), 1, [], [], 32, DEADLINE_S, "", scan)
    assert isinstance(refusal, TooSlow) and "its mesh file alone takes" in str(refusal)
    assert [p["field"] for p in refusal.field_problems()] == ["mesh"]


def test_a_preset_lit_by_its_lights_is_priced_under_an_environment_as_timed_under_one():
    """Light equivalents bound an environment's cost from above only: the sky-lit bunny on
    cd-rom-grating at 2048² drew in 0.61 s and was predicted at 10.9 s, over the deadline.
    The calibration times each such preset under the sky too, and those timings price it."""
    sky = ImageTask(prepare(RenderRequest(preset="sphere", environment="sky", width=192,
                                          height=192, samples=2), local_context(None)))
    assert sky.cost_label() == sky.cold_label() == "sphere+environment"
    assert sky.label == "sphere"  # the metrics' label
    timed = _calibration_task("sphere", environment="sky")
    found = model()
    found.calibrate(json.dumps({**CALIBRATION, "timings": {
        "sphere": [0.009, 0.033], "sphere+environment": [0.006, 0.02]},
        "cold_s": {"sphere": 0.02, "sphere+environment": 0.03, "morpho": 0.6},
        "light_load": {"sphere+environment": timed.light_load()}}).encode())
    assert found.predict(*timed.units()) == pytest.approx(1.5 * 0.006, rel=0.02)
    assert found.predict_task(sky) == pytest.approx(found.predict(*sky.units()) + 1.5 * 0.03)
    own = _calibration_task("soap-bubble")  # lit by the studio, as it was calibrated
    assert own.cost_label() == own.cold_label() == "soap-bubble"


def test_a_preset_timed_under_its_environment_is_not_charged_for_it_twice():
    """Morpho's calibration renders it under its studio, so its timing holds the studio's
    light equivalents already; before, they multiplied it again (morpho's standard 1024²,
    1.8 s, predicted at 24.6 s and refused under the 10 s deadline)."""
    tasks = [_calibration_task("morpho", w) for w in (0, 16)]
    assert min(task.light_load() for task in tasks) > 1.0  # the studio, in lights
    found = model()
    found.calibrate(json.dumps({**CALIBRATION, "timings": {"morpho": [0.1, 0.3]},
                                "light_load": {"morpho": min(t.light_load() for t in tasks)}}).encode())
    assert found.predict(*tasks[0].units()) <= 1.5 * 0.1 * 1.01
    brighter = ImageTask(prepare(CalibrateTask._request(get_preset("morpho"), 0).model_copy(
        update={"environment_lights": 64}), local_context(None)))
    assert found.predict(*brighter.units()) > 1.5 * 0.1 * 1.5  # more than it was timed with


# Legal requests over every cost driver (size, samples, wavelengths, grating orders,
# environment lights and lobe samples, the multi-peak lobe, a mesh file's parse and
# triangles), each a new render. Under a short deadline some are refused at once.
GRID = [
    {"width": 1024, "height": 1024, "quality": "standard"},
    {"width": 1024, "height": 1024, "samples": 4},
    {"width": 1024, "height": 1024, "samples": 16},
    {"width": 2048, "height": 2048, "quality": "draft"},
    {"width": 512, "height": 512, "wavelengths": 128},
    {"width": 256, "height": 256, "iridescence": "grating", "grating_orders": 8,
     "wavelengths": 128},
    {"width": 512, "height": 512, "iridescence": "grating", "grating_orders": 8},
    {"width": 512, "height": 512, "iridescence": "thin-film", "wavelengths": 128},
    {"width": 1024, "height": 1024, "iridescence": "thin-film", "wavelengths": 128},
    {"width": 512, "height": 512, "environment": "studio"},
    {"width": 512, "height": 512, "environment": "studio", "quality": "high"},
    {"width": 256, "height": 256, "environment": "studio", "environment_lights": 32},
    {"width": 512, "height": 512, "environment": "studio", "environment_lights": 64},
    {"width": 512, "height": 512, "environment": "studio", "mdf": "ashikhmin"},
    {"width": 512, "height": 512, "environment": "studio", "mdf": "ashikhmin",
     "environment_samples": 256},
    {"width": 512, "height": 512, "quality": "reference"},
    {"preset": "oil-film", "width": 512, "height": 512, "quality": "standard"},
    {"preset": "oil-film", "width": 1024, "height": 1024, "quality": "high"},
    {"mesh": "big", "width": 256, "height": 256, "quality": "draft"},
    {"mesh": "big", "width": 512, "height": 512, "quality": "standard"},
    {"mesh": "big", "width": 256, "height": 256, "iridescence": "grating",
     "grating_orders": 8},
]
GRID_DEADLINE_S = 3.0


def _render_s(answer) -> float:
    """The worker's part of a miss, from Server-Timing's ``render;dur=`` (ms)."""
    import re

    return float(re.search(r"render;dur=([0-9.]+)", answer.headers["server-timing"])[1]) / 1e3


@pytest.mark.gl
def test_no_admitted_request_runs_past_its_deadline(backend, tmp_path, tmp_path_factory,
                                                   capsys, monkeypatch):
    """Issue 24: over the grid, live, with this machine's calibration: each request is either
    refused at once (422 too_slow) or answered 200 within its deadline; what was admitted
    ran no longer than admission predicted, to within one timing's noise (the margins are
    printed). Before, a variant's first render (its compile) was not predicted: nacre's first
    standard 512² took 0.33 s against 0.05 predicted; and this test compared the warm
    prediction with that first render, which failed once a film's standard tier took the
    RGB fast path (oil-film's first standard 512², 0.16 s against 0.12). The workers start
    with an empty Mesa shader cache, as a fresh deployment does: with the calibration's
    programs in the machine's cache and the grid's not (OSMesa, after the suite's other
    tests), the calibration measured cached compiles and a grid request paid a real one,
    sphere under the studio with the A-S MDF at 512² 0.41 s against 0.33 predicted (0.07
    s once cached)."""
    import time

    import trimesh
    from fastapi.testclient import TestClient

    from opaline.pipeline.limits import Limits
    from opaline.pipeline.prepare import Context
    from opaline.server.api import create_app
    from opaline.settings import Settings

    monkeypatch.setenv("MESA_SHADER_CACHE_DIR", str(tmp_path_factory.mktemp("mesa-cache")))
    common = {"gl_backend": backend, "warmup": False, "workers": 1, "mesh_store_dir": tmp_path}
    with TestClient(create_app(Settings(**common, calibrate=False))) as client:
        big = trimesh.creation.icosphere(subdivisions=8).export(file_type="glb")  # 1.3M
        upload = client.post("/v1/meshes", content=big)  # its check is over 3 s
        assert upload.status_code == 201, upload.text
    rows = []
    settings = Settings(**common, calibrate=True, deadline_s=GRID_DEADLINE_S)
    with TestClient(create_app(settings)) as client:
        state = client.app.state
        context = Context(Limits(settings.cost_budget, settings.max_width, settings.max_height),
                          lambda r, p: state.meshes.preset(r, p, settings.mesh_max_triangles),
                          settings.environments_dir)
        deadline = time.monotonic() + 180  # the calibration's jobs: 33 s on OSMesa here
        while not client.get("/readyz").json().get("calibrated"):
            assert time.monotonic() < deadline, "the workers never calibrated"
            time.sleep(0.1)
        for n, fields in enumerate(GRID):
            body = {"preset": "sphere", **fields, "camera_azimuth": 10 + n}
            if body.get("mesh") == "big":
                body["mesh"] = upload.json()["id"]
            task = ImageTask(prepare(RenderRequest(**body), context))
            # What admission charges: a variant no worker has rendered yet pays its compile.
            predicted_s = state.pool.cost.predict_task(task)
            start = time.monotonic()
            answer = client.post("/v1/render", json=body)
            seconds = time.monotonic() - start
            if answer.status_code == 200:
                assert seconds <= GRID_DEADLINE_S, (fields, seconds)
                rows.append((fields, predicted_s, _render_s(answer)))
            else:
                assert answer.status_code == 422, (fields, answer.text)
                assert answer.json()["error"] == "too_slow", (fields, answer.text)
                assert seconds < 0.5, (fields, seconds)  # at once, before any worker
    margins = sorted(predicted / measured for _, predicted, measured in rows)
    with capsys.disabled():
        print(f"\n  admission grid ({GRID_DEADLINE_S:g} s deadline): {len(rows)} of {len(GRID)}"
              f" admitted, slowest {max(m for *_, m in rows):.2f} s; predicted / measured "
              f"{margins[0]:.2f} … {margins[-1]:.2f} (median {margins[len(margins) // 2]:.2f})")
    assert 3 <= len(rows) < len(GRID)  # the grid straddles the deadline
    # Never under, within the noise of one timing on a shared machine (oil-film's standard
    # 512², analytic AA where the calibration's variant had none, measured 0.92-1.09).
    assert margins[0] >= 0.8, [(f, round(p, 3), round(m, 3)) for f, p, m in rows if p < m]
