"""`from opaline import render`: a request in, the same bytes as every other path out."""

from __future__ import annotations

import io
import os
import subprocess
import sys
import threading
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from opaline.local import api as api_python
from opaline.model.params import RenderRequest
from opaline.model.presets import UnknownPreset

pytestmark = pytest.mark.gl
ROOT = Path(__file__).resolve().parents[2]
DISC = {"preset": "cd-rom", "mu_f": 6, "width": 64, "height": 48, "quality": "draft"}


@pytest.fixture(scope="module")
def on_thread(backend):
    """Runs calls on one dedicated thread, so its context never meets the session's."""
    pool = ThreadPoolExecutor(1)

    def call(fn, *args, **kwargs):
        kwargs.setdefault("backend", backend)
        return pool.submit(fn, *args, **kwargs).result()

    yield call
    pool.submit(api_python.close).result()
    pool.shutdown()


def test_importing_opaline_stays_light():
    """`import opaline` loads no GL, NumPy or pydantic; `opaline.render` loads them on use."""
    code = ("import sys, opaline; heavy = {'moderngl', 'numpy', 'pydantic'} & set(sys.modules); "
            "assert not heavy, heavy; from opaline import render, render_array; "
            "import opaline.local.api as api; "
            "assert render is api.render and 'moderngl' in sys.modules; "
            "assert render_array is api.render_array")
    result = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                            text=True, timeout=60)
    assert result.returncode == 0, result.stderr


def test_a_thread_that_ends_releases_its_context(backend):
    """A thread that rendered and ended without close() gave its GL context back (each
    such thread kept ~6 MB for the life of the process); one that closed is not released
    twice; the main thread's renderer outlives the others. In a process of its own: the
    contexts are made and released as a user's threads would."""
    code = f"""
import threading
from opaline.local import api
SMALL = {{"preset": "sphere", "width": 16, "height": 16, "quality": "draft"}}
seen = []
def work(closes):
    api.render(SMALL, backend={backend!r})
    seen.append(api.renderer({backend!r}).renderer.ctx)
    if closes:
        api.close()
api.render(SMALL, backend={backend!r})
for closes in (False, True, False):
    thread = threading.Thread(target=work, args=(closes,))
    thread.start()
    thread.join()
assert [type(ctx.mglo).__name__ for ctx in seen] == ["InvalidObject"] * 3
assert type(api.renderer({backend!r}).renderer.ctx.mglo).__name__ == "Context"
assert api.render(SMALL, backend={backend!r}).startswith(b"\\x89PNG")
"""
    result = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                            text=True, timeout=120)
    assert result.returncode == 0, result.stderr


def test_a_fork_does_not_release_the_parents_contexts(backend, tmp_path):
    """A fork drops the other threads' locals in the child, on its main thread: the release
    at a thread's end ran there, on a copy of the parent's GL state, from a thread that did
    not own the context (a review found it). In the child it is skipped."""
    marker = tmp_path / "released"
    code = f"""
import os, threading
from opaline.local import api, pipeline
closing = pipeline.LocalRenderer.close
def close(self):
    with open({str(marker)!r}, "a") as out:
        out.write(f"{{os.getpid()}}\\n")
    closing(self)
pipeline.LocalRenderer.close = close
rendered, done = threading.Event(), threading.Event()
def work():
    api.render({{"preset": "sphere", "width": 16, "height": 16}}, backend={backend!r})
    rendered.set()
    done.wait()
thread = threading.Thread(target=work)
thread.start()
rendered.wait()
child = os.fork()
if child == 0:
    os._exit(0)
os.waitpid(child, 0)
done.set()
thread.join()
print(os.getpid())
"""
    result = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                            text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert marker.read_text().split() == [result.stdout.strip()]  # the parent's own, once


def test_unknown_attribute_of_opaline_is_an_attribute_error():
    """The lazy `opaline.__getattr__` still raises AttributeError for names it does not know."""
    import opaline

    with pytest.raises(AttributeError):
        opaline.no_such_thing  # noqa: B018


def test_render_dict_gives_a_png_of_the_requested_size(on_thread):
    """render(dict) returns PNG bytes of the request's size with a visible object."""
    data = on_thread(api_python.render, DISC)
    with Image.open(io.BytesIO(data)) as image:
        assert image.format == "PNG" and image.size == (64, 48)
        assert np.asarray(image.convert("RGB")).std() > 5


def test_render_matches_local_renderer_bytes(on_thread, backend):
    """The Python API, a RenderRequest and a dict all give the LocalRenderer's exact bytes."""
    from opaline.local.pipeline import LocalRenderer

    def local_bytes(backend):
        with LocalRenderer(backend) as renderer:
            return renderer.render_bytes(RenderRequest(**DISC))

    expected = ThreadPoolExecutor(1).submit(local_bytes, backend).result()
    assert on_thread(api_python.render, DISC) == expected
    assert on_thread(api_python.render, RenderRequest(**DISC)) == expected


def test_render_array_is_linear_float_rgba(on_thread):
    """render_array gives (H, W, 4) float32, finite, non-negative, whatever the format asked."""
    array = on_thread(api_python.render_array, {**DISC, "format": "png"})
    assert array.shape == (48, 64, 4) and array.dtype == np.float32
    assert np.isfinite(array).all() and (array >= 0).all() and array[..., 3].max() > 0.5


def test_render_of_a_material_file_path(on_thread, tmp_path):
    """A pathlib.Path is read as a material file."""
    path = tmp_path / "disc.toml"
    path.write_text('preset = "cd-rom"\nmu_f = 6\nwidth = 64\nheight = 48\nquality = "draft"\n')
    assert on_thread(api_python.render, path) == on_thread(api_python.render, DISC)


def test_render_of_a_material_file_given_as_str(on_thread, tmp_path):
    """A str ending .json/.toml is a material file's path, read like a Path."""
    path = tmp_path / "ball.json"
    path.write_text('{"preset": "cd-rom", "mu_f": 6, "width": 64, "height": 48, '
                    '"quality": "draft"}')
    assert on_thread(api_python.render, str(path)) == on_thread(api_python.render, DISC)
    with pytest.raises(api_python.RequestError, match="cannot read"):
        on_thread(api_python.render, str(tmp_path / "missing.toml"))


def test_cost_budget_comes_from_the_environment(on_thread, cost_budget):
    """OPALINE_COST_BUDGET bounds the Python API as it bounds the HTTP service."""
    from opaline.model.request import CostError

    small = {**DISC, "width": 32, "height": 32, "wavelengths": 0}  # 32×32×1 sample×3 = 3072
    cost_budget(3000)
    with pytest.raises(CostError, match="over the budget of 3000"):
        on_thread(api_python.render, small)
    cost_budget(4000)
    assert on_thread(api_python.render, small).startswith(b"\x89PNG")


def test_plain_render_prints_no_third_party_warning():
    """A spectral render without matplotlib (not a dependency) prints nothing on stderr, even
    with every warning shown: colour-science's "Matplotlib ... not available" is silenced."""
    code = ("import sys; sys.modules['matplotlib'] = None\n"  # as on a plain install
            "from opaline import render\n"
            "render({'preset': 'cd-rom', 'width': 16, 'height': 16, 'quality': 'draft', "
            "'wavelengths': 4})\n")
    result = subprocess.run([sys.executable, "-W", "default", "-c", code], cwd=ROOT,
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""


def test_public_api_is_typed_for_type_checkers(tmp_path):
    """mypy sees render's real signature through `from opaline import render` (not Any)."""
    pytest.importorskip("mypy")
    use = tmp_path / "use.py"
    use.write_text("from opaline import render, render_array\n"
                   "data: bytes = render('ball.json')\n"
                   "array = render_array({'preset': 'cd-rom'}, backend='osmesa')\n"
                   "wrong: int = render({'preset': 'cd-rom'})\n"
                   "render(42)\n")
    result = subprocess.run(
        [sys.executable, "-m", "mypy", "--no-incremental", "--follow-imports=silent",
         "--no-error-summary", str(use)],
        cwd=tmp_path, capture_output=True, text=True, timeout=120,
        env={**os.environ, "MYPYPATH": str(ROOT / "service")})
    errors = [line for line in result.stdout.splitlines() if ": error:" in line]
    assert [e.split(":")[1] for e in errors] == ["4", "5"], result.stdout


def test_invalid_request_raises_with_field_value_and_range(on_thread):
    """An out-of-range value raises RequestError naming it; nothing is clamped."""
    with pytest.raises(api_python.RequestError) as info:
        on_thread(api_python.render, {**DISC, "mu_f": 5000, "width": 4})
    assert any("mu_f=5000 is out of range: allowed [0 … 1000]" in p for p in info.value.problems)
    assert any(p.startswith("width=4") for p in info.value.problems)
    assert isinstance(info.value, ValueError)


@pytest.mark.parametrize("field, value", [("mu_f", True), ("mu_f", "6"), ("width", "32"),
                                          ("transparent", "yes")])
def test_values_are_read_as_a_json_body_reads_them(field, value):
    """A string for a number or for a boolean, or a boolean for a number, is refused as
    POST /v1/render and a material file refuse it; before, the Python API took them (True
    drew mu_f=1)."""
    with pytest.raises(api_python.RequestError) as info:
        api_python.as_request({"preset": "cd-rom", field: value})
    assert info.value.problems[0].startswith(f"{field}=")


def test_numpy_numbers_and_python_tuples_are_read():
    request = api_python.as_request({"preset": "cd-rom", "mu_f": np.float32(2.5),
                                     "width": np.int64(64), "albedo": np.array([0.1, 0.2, 0.5]),
                                     "metal_f0": (0.9, 0.6, 0.5), "height": 48.0})
    assert (request.mu_f, request.width, request.height) == (2.5, 64, 48)
    assert request.albedo == pytest.approx((0.1, 0.2, 0.5))


def test_unknown_preset_and_wrong_type_raise(on_thread):
    """An unknown preset raises UnknownPreset; a non-request argument raises TypeError."""
    with pytest.raises(UnknownPreset):
        on_thread(api_python.render, {"preset": "nope"})
    with pytest.raises(TypeError):
        on_thread(api_python.render, "cd-rom")


def test_one_renderer_per_thread_each_correct(on_thread, backend):
    """Each thread gets its own renderer, reused for its calls, and the same bytes."""
    first = on_thread(api_python.render, DISC)
    seen = {}

    def worker(index):
        api_python.render(DISC, backend=backend)
        seen[index] = (api_python.renderer(backend), api_python.render(DISC, backend=backend))
        api_python.close()

    threads = [threading.Thread(target=worker, args=(i,)) for i in range(2)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=60)
    assert seen[0][0] is not seen[1][0]
    assert seen[0][1] == seen[1][1] == first


def test_another_context_on_the_thread_does_not_corrupt_renders(on_thread, backend):
    """A second GL context made on the same thread (which becomes current) changes nothing."""
    from opaline.gl.context import create_context

    def with_intruder(backend):
        before = api_python.render(DISC, backend=backend)
        intruder = create_context(backend)
        try:
            return before, api_python.render(DISC, backend=backend)
        finally:
            intruder.release()

    before, after = on_thread(with_intruder)
    assert before == after


def test_exports_and_turntables_read_requests_as_render_does():
    """export_material took any kind but "glsl" for a .glb ("GLSL", "fbx") and, with
    render_turntable, took {"mu_f": "6"} and {"mu_f": True}, which render() refuses; an
    out-of-range value raised pydantic's own error, not RequestError."""
    from opaline import export_material, render_turntable

    for kind in ("GLSL", "fbx"):
        with pytest.raises(ValueError, match="expected one of glsl, glb"):
            export_material({"preset": "sphere"}, kind)
    for loose in ({"mu_f": "6"}, {"mu_f": True}, {"mu_f": 5000}):
        with pytest.raises(api_python.RequestError, match="mu_f"):
            export_material({"preset": "cd-rom", **loose}, "glsl")
        with pytest.raises(api_python.RequestError, match="mu_f"):
            render_turntable({"preset": "cd-rom", "frames": 2, "width": 16, "height": 16,
                              **loose})
    assert export_material({"preset": "cd-rom", "mu_f": 6}, "glsl").startswith(b"//")
