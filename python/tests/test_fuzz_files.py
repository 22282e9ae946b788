"""Random text and mutated model files through the string loaders: only ValueError comes out
(never another exception, a crash or a Rust panic). The core crate's own fuzzer
(crates/robodyn/tests/fuzz.rs, scripts/fuzz) runs far more cases without Python."""

from __future__ import annotations

import pytest
from conftest import REPOSITORY
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import robodyn

FILES = {
    "urdf": sorted((REPOSITORY / "models").glob("*.urdf")),
    "mjcf": sorted((REPOSITORY / "testdata" / "mjcf").glob("*.xml")),
}
LOADERS = {"urdf": robodyn.load_urdf_string, "mjcf": robodyn.load_mjcf_string}
#: Hypothesis examples per test (the test command must stay fast)
EXAMPLES = 150


def loads_or_value_error(kind: str, text: str) -> None:
    try:
        LOADERS[kind](text)
    except ValueError:
        pass


@pytest.mark.parametrize("kind", sorted(LOADERS))
@settings(max_examples=EXAMPLES, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.binary(max_size=2000))
def test_random_bytes_give_only_value_errors(kind, data):
    loads_or_value_error(kind, data.decode("utf-8", errors="replace"))


@st.composite
def mutated_file(draw, kind):
    text = draw(st.sampled_from(FILES[kind])).read_text()
    for _ in range(draw(st.integers(1, 4))):
        start = draw(st.integers(0, len(text)))
        end = draw(st.integers(start, min(len(text), start + 40)))
        replacement = draw(st.one_of(
            st.text(max_size=20),
            st.sampled_from(["1e308", "-1", "nan", "inf", "<body>", "</link>", "<joint/>", '"', "<", "&amp;", "0 0"]),
            st.just(text[start:end] * draw(st.integers(2, 50))),
        ))
        text = text[:start] + replacement + text[end:]
    return text


@pytest.mark.parametrize("kind", sorted(LOADERS))
@settings(max_examples=EXAMPLES, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_mutated_model_files_give_only_value_errors(kind, data):
    loads_or_value_error(kind, data.draw(mutated_file(kind)))
