"""Integer keyword arguments (size, jobs, steps, width, height): a negative, huge or
non-integer value raises a ValueError (InvalidInputError) or TypeError naming the argument,
never a bare OverflowError, and before any work; the Renderer stays usable afterwards."""

import numpy as np
import pytest

import viewsynth as vs
from conftest import make_frame

U32_MAX, U64_MAX = 2**32 - 1, 2**64 - 1


def calls(renderer, tmp_path):
    """(argument, call) pairs: each call passes the value under test to that argument only."""
    rgb, depth, K = make_frame(width=32, height=24)
    # Never looked at: the integer argument is refused first.
    faces = np.zeros((6, 8, 8, 3), np.uint8), np.full((6, 8, 8), 2.0, np.float32)
    out = tmp_path / "out"
    return [
        ("size", U32_MAX, lambda v: renderer.refocus(rgb, depth, K, scales=[1.0], size=(v, 10))),
        ("size", U32_MAX, lambda v: renderer.refocus(rgb, depth, K, scales=[1.0], size=(10, v))),
        ("steps", U32_MAX, lambda v: renderer.reproject(rgb, depth, K, baseline=0.1, steps=v)),
        ("width", U32_MAX, lambda v: renderer.stitch(*faces, *faces, width=v, height=16)),
        ("height", U32_MAX, lambda v: renderer.stitch(*faces, *faces, width=32, height=v)),
        ("jobs", U64_MAX, lambda v: renderer.refocus_batch([], out, jobs=v)),
        ("size", U32_MAX, lambda v: renderer.refocus_batch([], out, size=(v, 10))),
    ]


@pytest.mark.parametrize("case", ["-1", "-2**70", "max+1", "2**70"])
def test_out_of_range_integers_are_value_errors_naming_the_argument(renderer, tmp_path, case):
    for name, most, call in calls(renderer, tmp_path):
        value = {"-1": -1, "-2**70": -(2**70), "max+1": most + 1, "2**70": 2**70}[case]
        with pytest.raises(ValueError) as err:
            call(value)
        assert not isinstance(err.value, OverflowError), (name, err.value)
        assert isinstance(err.value, vs.InvalidInputError), (name, type(err.value))
        message = str(err.value)
        assert name in message and str(value) in message, (name, message)
        assert err.value.parameter.startswith(name), (name, err.value.parameter)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("value", [1.5, 3.0, "3", True, None])
def test_non_integers_are_type_errors_naming_the_argument(renderer, tmp_path, value):
    for name, _, call in calls(renderer, tmp_path):
        if value is None and name == "jobs":
            continue  # None is its default
        with pytest.raises(TypeError) as err:
            call(value)
        assert name in str(err.value), (name, str(err.value))


def test_size_must_be_a_pair(renderer, frame):
    rgb, depth, K = frame
    for bad, words in [((10,), "1 items"), ((1, 2, 3), "3 items")]:
        with pytest.raises(vs.InvalidInputError) as err:
            renderer.refocus(rgb, depth, K, scales=[1.0], size=bad)
        assert "size" in str(err.value) and words in str(err.value), str(err.value)
    with pytest.raises(TypeError, match="size"):
        renderer.refocus(rgb, depth, K, scales=[1.0], size=7)


def test_numpy_integers_and_the_renderer_afterwards(renderer, frame):
    rgb, depth, K = frame
    views = renderer.refocus(rgb, depth, K, scales=[1.0], size=(np.int64(40), np.uint16(30)))
    assert views[0]["rgb"].shape == (30, 40, 3)
