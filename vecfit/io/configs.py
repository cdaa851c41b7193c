"""The packaged default settings (configs/*.toml, installed as vecfit.configs) and TOML
reading. The defaults live only in those files: every settings class builds its default
from here (``defaults``), and vecfit.jobs.config layers presets, the user's file and the
command line over them."""
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


@functools.lru_cache(maxsize=None)
def _packaged(command: str) -> dict:
    return read_toml(configs_dir() / f"{command}.toml")


def defaults(command: str, table: str) -> dict:
    """The default ``[table]`` of ``command``: refine.toml's table (what every command starts
    from) updated by the command's own file, presets aside; nested tables (optimize.lr)
    are updated key by key."""
    out = copy.deepcopy(_packaged("refine").get(table, {}))
    if command != "refine":
        _update(out, _packaged(command).get(table, {}))
    return out


def _update(base: dict, changes: dict) -> None:
    for key, value in changes.items():
        if isinstance(value, dict) and isinstance(base.get(key), dict):
            _update(base[key], value)
        else:
            base[key] = copy.deepcopy(value)
