"""The packaged default settings (configs/*.toml, installed as vecfit.configs), TOML
reading, and the one merge of settings tables. The defaults live only in those files:
every settings class builds its default from here (``defaults``), and vecfit.jobs.config
layers efforts, presets, the user's file and the command line over them with the same
``merge``."""
from __future__ import annotations

import copy
import functools
import importlib.resources
import tomllib

from vecfit.errors import VecfitError


def configs_dir():
    """The default settings: the package vecfit.configs, which the wheel and the editable
    install both map to the repository's configs/ (pyproject.toml's wheel.packages)."""
    try:
        root = importlib.resources.files("vecfit.configs")
    except ModuleNotFoundError:
        root = None
    if root is None or not (root / "refine.toml").is_file():
        raise VecfitError("the default settings (vecfit/configs/refine.toml) are missing from "
                          "this installation: reinstall vecfit")
    return root


def read_toml(path) -> dict:
    try:
        with open(path, "rb") as f:
            return tomllib.load(f)
    except FileNotFoundError:
        raise VecfitError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise VecfitError(f"{path}: is a folder, not a TOML file") from None
    except tomllib.TOMLDecodeError as e:
        raise VecfitError(f"{path}: not valid TOML ({e})") from None
    except (OSError, UnicodeDecodeError) as e:
        raise VecfitError(f"{path}: cannot read ({e})") from None


def merge(base: dict, changes: dict, schema: dict, source: str, prefix: str = "") -> dict:
    """``base`` updated with ``changes`` (nested tables key by key), each key checked against
    ``schema`` (the defaults): an unknown key, or a value of another type, is an error
    naming ``source`` (the file) and the key, not a setting silently ignored."""
    out = copy.deepcopy(base)
    for key, value in changes.items():
        name = f"{prefix}{key}"
        if key not in schema:
            known = ", ".join(sorted(schema))
            raise VecfitError(f"{source}: unknown setting {name!r} (known here: {known})")
        expected = schema[key]
        if isinstance(expected, dict):
            if not isinstance(value, dict):
                raise VecfitError(f"{source}: {name} must be a table")
            out[key] = merge(out.get(key, {}), value, expected, source, name + ".")
        else:
            out[key] = copy.deepcopy(_checked(value, expected, name, source))
    return out


# Settings whose default is "auto" and that take a number instead (their range is checked
# with the other settings: vecfit/fitting/settings.py).
AUTO_OR_NUMBER = {"optimize.target_blur"}


def _checked(value, expected, name: str, source: str):
    if name in AUTO_OR_NUMBER:
        ok = value == "auto" or (isinstance(value, (int, float)) and not isinstance(value, bool))
        if not ok:
            raise VecfitError(f'{source}: {name} must be "auto" or a number, not {value!r}')
        return value if value == "auto" else float(value)
    if isinstance(expected, bool):
        ok = isinstance(value, bool)
    elif isinstance(expected, float):
        ok = isinstance(value, (int, float)) and not isinstance(value, bool)
        value = float(value) if ok else value
    elif isinstance(expected, int):
        ok = isinstance(value, int) and not isinstance(value, bool)
    else:
        ok = isinstance(value, type(expected))
    if not ok:
        raise VecfitError(f"{source}: {name} must be {type(expected).__name__}, not {value!r}")
    return value


@functools.lru_cache(maxsize=None)
def packaged(command: str) -> tuple[dict, dict, dict, dict]:
    """``command``'s packaged settings as (settings, schema, efforts, presets): refine.toml
    (what every command starts from) merged with the command's own file, whose own tables
    join the schema (every key a user may set, with its type); its ``[efforts.NAME]`` and
    ``[presets.NAME]`` tables apart. Cached: copy before changing."""
    settings = read_toml(configs_dir() / "refine.toml")
    efforts = settings.pop("efforts", {})
    presets: dict = {}
    schema = copy.deepcopy(settings)
    if command != "refine":
        own = read_toml(configs_dir() / f"{command}.toml")
        presets = own.pop("presets", {})
        efforts = own.pop("efforts", {})
        for key, value in own.items():  # the command's own tables join the schema
            if key not in schema:
                if not isinstance(value, dict):
                    raise VecfitError(f"configs/{command}.toml: {key!r} must be inside a table")
                schema[key] = copy.deepcopy(value)
        settings = merge(settings, own, schema, f"configs/{command}.toml")
    return settings, schema, efforts, presets


def defaults(command: str, table: str) -> dict:
    """The default ``[table]`` of ``command`` (``packaged``: refine.toml's table updated by
    the command's own file, efforts and presets aside)."""
    return copy.deepcopy(packaged(command)[0].get(table, {}))
