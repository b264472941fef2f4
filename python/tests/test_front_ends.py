"""The Python half of the front-end mapping test (the CLI half: src/bin/viewsynth/front_ends.rs).

Both read tests/data/front_ends.json: for each command with a library request, the option and
keyword argument that fill each request field, and everything on one side only, with its reason.
Here: every keyword argument of the Renderer method is a request field's or listed Python-only,
every field's argument exists, and each argument's default is the library request's default.
"""

import inspect
import json
from pathlib import Path

import pytest

import viewsynth as vs
from viewsynth import _viewsynth

TABLE = json.loads((Path(__file__).resolve().parents[2] / "tests" / "data" / "front_ends.json").read_text())


def test_every_request_command_is_in_the_table():
    assert set(_viewsynth._REQUEST_COMMANDS) <= set(TABLE)


@pytest.mark.parametrize("command", _viewsynth._REQUEST_COMMANDS)
def test_keyword_arguments_map_to_request_fields_with_the_library_defaults(command):
    entry = TABLE[command]
    defaults = json.loads(_viewsynth._request_defaults(command))
    assert set(defaults) == set(entry["fields"]), "the request's fields and the table's differ"
    params = inspect.signature(getattr(vs.Renderer, entry["python_method"])).parameters
    names = [n for n in params if n != "self"]
    by_keyword = {}
    for field, spec in entry["fields"].items():
        keyword = spec.get("python")
        if keyword is None:
            assert spec.get("why"), f"{field}: no keyword argument and no reason"
            continue
        assert keyword in params, f"{command}: the table maps {field} to {keyword}, which Python lacks"
        by_keyword[keyword] = field
    for name in names:
        reason = entry["python_only"].get(name)
        assert name in by_keyword or reason, f"{command}({name}=...): neither a request field's nor listed Python-only"
    for name in entry["python_only"]:
        assert name in params, f"{command}: the table lists {name}, which Python lacks"
    for keyword, field in by_keyword.items():
        default = params[keyword].default
        want = defaults[field]
        if isinstance(want, float) and isinstance(default, (int, float)) and not isinstance(default, bool):
            assert float(default) == want, (command, keyword, default, want)
        else:
            assert default == want, f"{command}({keyword}=...) defaults to {default!r}, the request to {want!r}"
