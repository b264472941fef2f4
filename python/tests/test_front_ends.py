"""The Python half of the front-end mapping test (the CLI half: cli/src/front_ends.rs).

Both read tests/data/front_ends.json: for each command with a library request, the option and
keyword argument that fill each request field, and everything on one side only, with its reason.
Here, for each Renderer method of the command: every keyword argument is a request field's or
listed as the method's own, every field is an argument or listed absent with a reason, and each
argument's default is the library request's default.
"""

import inspect
import json
from pathlib import Path

import pytest

import viewsynth as vs
from viewsynth import _viewsynth

TABLE = json.loads((Path(__file__).resolve().parents[2] / "tests" / "data" / "front_ends.json").read_text())
METHODS = [(command, method) for command in _viewsynth._REQUEST_COMMANDS
           for method in TABLE[command]["python_methods"]]


def test_every_request_command_is_in_the_table():
    assert set(_viewsynth._REQUEST_COMMANDS) <= set(TABLE)


@pytest.mark.parametrize("command,method", METHODS)
def test_keyword_arguments_map_to_request_fields_with_the_library_defaults(command, method):
    entry = TABLE[command]
    spec = entry["python_methods"][method]
    defaults = json.loads(_viewsynth._request_defaults(command))
    assert set(defaults) == set(entry["fields"]), "the request's fields and the table's differ"
    params = inspect.signature(getattr(vs.Renderer, method)).parameters
    names = [n for n in params if n != "self"]
    by_keyword = {}
    for field, field_spec in entry["fields"].items():
        keyword = field_spec.get("python")
        if keyword is None or field in spec["absent"]:
            assert spec["absent"].get(field) or field_spec.get("why"), f"{method}: {field} absent without a reason"
            assert keyword not in params or keyword is None, f"{method}: {keyword} exists but is listed absent"
            continue
        assert keyword in params, f"{method}: the table maps {field} to {keyword}, which Python lacks"
        # Errors name a request's options as the keyword arguments that give them.
        if field_spec.get("cli"):
            assert _viewsynth._keyword(field_spec["cli"][0]) == keyword, (field_spec["cli"][0], keyword)
        by_keyword[keyword] = field
    for name in names:
        assert name in by_keyword or spec["only"].get(name), \
            f"{method}({name}=...): neither a request field's nor listed as the method's own"
    for name in spec["only"]:
        assert name in params, f"{method}: the table lists {name}, which Python lacks"
    for keyword, field in by_keyword.items():
        default = params[keyword].default
        want = defaults[field]
        if isinstance(want, float) and isinstance(default, (int, float)) and not isinstance(default, bool):
            assert float(default) == want, (method, keyword, default, want)
        else:
            assert default == want, f"{method}({keyword}=...) defaults to {default!r}, the request to {want!r}"
