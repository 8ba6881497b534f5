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


def read_pickle(path: str | Path, made_by: str, lists: tuple[str, ...]) -> dict:
    """The dict pickled at ``path`` by the command ``made_by``, holding a list under each key of ``lists``; a
    missing file, a foreign pickle or another object is an InputError naming the file and that command."""
    import pickle

    path = Path(path)
    if not path.is_file():
        raise InputError(path, f"no such file (make it with {made_by})")
    try:
        data = pickle.loads(path.read_bytes())
    except Exception as e:  # noqa: BLE001 - whatever a foreign file raises, the answer is one line
        raise InputError(path, f"not a pickle of {made_by} ({type(e).__name__})") from None
    if not isinstance(data, dict) or not all(isinstance(data.get(k), list) for k in lists):
        raise InputError(path, f"not a pickle of {made_by} (no {' and '.join(lists)})")
    return data
