"""One error type for bad input: the CLI prints it as one line and exits non-zero."""

from __future__ import annotations

from pathlib import Path


class InputError(Exception):
    """Bad user input. ``where`` names the file or option, ``problem`` says what is wrong."""

    def __init__(self, where: str | Path, problem: str):
        self.where = str(where)
        self.problem = problem
        super().__init__(f"{self.where}: {problem}")


def read_json(path: str | Path, what: str = "JSON file"):
    """Parse the JSON file at ``path``; a missing or malformed file is an InputError naming it."""
    import json

    path = Path(path)
    if not path.is_file():
        raise InputError(path, f"{what} not found")
    try:
        return json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        raise InputError(path, f"{what} is not valid JSON: {e}") from None
