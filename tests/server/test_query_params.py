"""query_model reads a query string as FastAPI's own Query() model would, and documented()
lists the parameters FastAPI would: two routes, one each way, must answer alike."""

# No `from __future__ import annotations`: the routes below are declared in a loop, and
# FastAPI must see each one's model, not the name `model`.
from typing import Annotated

import pytest
from fastapi import Depends, FastAPI, Query
from fastapi.exceptions import RequestValidationError
from fastapi.testclient import TestClient
from hypothesis import given
from hypothesis import strategies as st

from opaline.server.canonical import CanonicalMdfQuery, CanonicalQuery
from opaline.server.errors import on_invalid
from opaline.server.query_params import documented, query_model

MODELS = {"render": CanonicalQuery, "mdf": CanonicalMdfQuery}


def twin_app() -> FastAPI:
    """/fastapi/NAME reads the model FastAPI's way, /ours/NAME through query_model; both
    answer what they read, and a 422 in the service's own shape."""
    app = FastAPI()
    app.state.metrics = type("Quiet", (), {"reject": staticmethod(lambda reason: None)})()
    app.add_exception_handler(RequestValidationError, on_invalid)
    for name, model in MODELS.items():
        def theirs(q: Annotated[model, Query()]) -> dict:  # type: ignore[valid-type]
            return q.model_dump(mode="json")

        def ours(q: Annotated[model, Depends(query_model(model))]) -> dict:  # type: ignore[valid-type]
            return q.model_dump(mode="json")

        app.add_api_route(f"/fastapi/{name}", theirs)
        app.add_api_route(f"/ours/{name}", ours, openapi_extra=documented(model))
    return app


CLIENT = TestClient(twin_app())
CASES = [
    "", "preset=sphere", "width=abc", "width=5", "width=256&width=128", "albedo=0.1,0.2,0.3",
    "albedo=0.1&albedo=0.2&albedo=0.3", "albedo=0.1,0.2", "albedo=2,0,0", "albedo=",
    "bogus=1", "bogus=1&bogus=2", "mu_f=-1&exposure=x", "tangent_axis=0,0,1",
    "tangent_axis=0&tangent_axis=0&tangent_axis=1", "quality=draft&samples=4",
    "quality=auto&max_flip=0.05", "wavelengths=3", "rev=abc", "rev=" + "0" * 32,
    "exposure=1e400", "exposure=nan", "width=", "size=64", "size=1", "format=npy",
]


def answers(name: str, query: str) -> tuple[tuple[int, object], tuple[int, object]]:
    theirs = CLIENT.get(f"/fastapi/{name}?{query}")
    ours = CLIENT.get(f"/ours/{name}?{query}")
    return (theirs.status_code, theirs.json()), (ours.status_code, ours.json())


@pytest.mark.parametrize("name", MODELS)
@pytest.mark.parametrize("query", CASES)
def test_query_model_answers_as_fastapi_does(name, query):
    theirs, ours = answers(name, query)
    assert ours == theirs


@given(st.lists(st.tuples(st.sampled_from(["width", "albedo", "mu_f", "tangent_axis", "size",
                                           "quality", "x", "format", "rev"]),
                          st.sampled_from(["", "1", "0.5", "256", "0,0,1", "draft", "png",
                                           "-3", "a"])), max_size=5))
def test_any_mix_of_names_and_values_is_read_alike(pairs):
    query = "&".join(f"{name}={value}" for name, value in pairs)
    for name in MODELS:
        theirs, ours = answers(name, query)
        assert ours == theirs, query


def test_the_documented_parameters_are_fastapis():
    paths = CLIENT.app.openapi()["paths"]
    for name in MODELS:
        theirs = paths[f"/fastapi/{name}"]["get"]["parameters"]
        assert paths[f"/ours/{name}"]["get"]["parameters"] == theirs
        assert len(theirs) == len(MODELS[name].model_fields)
