"""Settings of the optimising commands, from TOML files in configs/.

Resolution, last wins: configs/refine.toml (the optimisation defaults every command starts
from), the command's own file (configs/trace.toml, ...), the effort (``--effort
quick|normal|best``: that file's ``[efforts.NAME]`` table; normal is the file as it is), a
preset from that file's ``[presets.NAME]`` tables, the user's ``--config`` file, then
command-line options. Every key must exist in the defaults, with a value of the same type,
so a typo is an error naming the file and the key rather than a setting silently ignored.
The resolved settings carry the effort used as their ``effort`` entry (so reports and
batch resumes see it).
"""
from __future__ import annotations

import copy
import dataclasses

from vecfit.errors import VecfitError
from vecfit.fitting.settings import Settings  # torch-free: trace --no-refine checks it too
from vecfit.io.configs import configs_dir, merge, packaged, read_toml  # noqa: F401 (configs_dir: for callers)
from vecfit.names import EFFORTS, GROUP_BY, MAX_DECIMALS, STACKINGS

DEFAULT_EFFORT = "normal"


def resolve(command: str, *, preset: str | None = None, config_file=None,
            overrides: dict | None = None, effort: str | None = None) -> dict:
    """The settings of ``command`` (refine, trace, paint, edit, retarget): defaults, its file,
    the effort, a preset, the user's file and the overrides (a nested dict like the files), in
    that order. ``effort`` None: the user's file's top-level ``effort``, else normal."""
    settings, schema, efforts, presets = packaged(command)
    user = None if config_file is None else read_toml(config_file)
    if user is not None and "effort" in user:
        chosen = user.pop("effort")
        if not isinstance(chosen, str):
            raise VecfitError(f"{config_file}: effort must be str, not {chosen!r}")
        effort = chosen if effort is None else effort  # an --effort option wins over the file
    effort = DEFAULT_EFFORT if effort is None else effort
    if effort not in EFFORTS:
        raise VecfitError(f"unknown effort {effort!r} (known: {', '.join(EFFORTS)})")
    settings = copy.deepcopy(settings)
    if effort != DEFAULT_EFFORT:
        if effort not in efforts:
            raise VecfitError(f"effort {effort!r} is not defined for {command} (configs/{command}.toml "
                              f"has no [efforts.{effort}] table)")
        settings = merge(settings, efforts[effort], schema, f"effort {effort!r}")
    if preset is not None:
        if preset not in presets:
            known = ", ".join(sorted(presets)) or "none"
            raise VecfitError(f"unknown preset {preset!r} for {command} (known: {known})")
        settings = merge(settings, presets[preset], schema, f"preset {preset!r}")
    if user is not None:
        settings = merge(settings, user, schema, str(config_file))
    if overrides:
        settings = merge(settings, _drop_none(overrides), schema, "command line")
    validate(settings)
    if settings["output"]["stacking"] != "stacked" and command not in ("trace", "refine", "paint"):
        raise VecfitError(f"output.stacking = cutouts is for trace, refine and paint ({command} keeps the "
                          "file's own elements)")
    settings["effort"] = effort
    return settings


def validate(settings: dict) -> None:
    """Checks the values, not just the keys and types: a bad background, loss, rate, trace
    or paint setting is refused here, before any work starts (VecfitError), and only here:
    the jobs take what ``resolve`` returns as checked. [optimize] is checked by its type,
    Settings."""
    Settings.from_config(settings["optimize"])
    from vecfit.jobs.palette import parse_palette  # an unreadable or empty palette: refused before any work
    parse_palette(settings["optimize"]["palette"])
    if settings["output"]["group_by"] not in GROUP_BY:
        raise VecfitError(f"output.group_by must be none or colour, not {settings['output']['group_by']!r}")
    if settings["output"]["stacking"] not in STACKINGS:
        raise VecfitError(f"output.stacking must be {' or '.join(STACKINGS)}, not {settings['output']['stacking']!r}")
    if settings["output"]["stacking"] == "cutouts" and settings.get("trace", {}).get("style", "fills") != "fills":
        raise VecfitError("cut-outs are filled pieces: --stacking cutouts needs --style fills")
    if settings["output"]["gap_filler"] and settings["output"]["stacking"] != "cutouts":
        raise VecfitError("output.gap_filler (--gap-filler) is for cut-outs (--stacking cutouts)")
    output_precision(settings)
    seed = settings["optimize"]["seed"]
    if "trace" in settings:
        from vecfit.initial.tracer import TraceSettings
        settings_of(TraceSettings, settings["trace"], seed=seed)  # (checked as it is made)
    if "paint" in settings:
        from vecfit.initial.strokes import PaintSettings
        settings_of(PaintSettings, settings["paint"], seed=seed).check()
    if "edit" in settings:
        from vecfit.editing.settings import EditSettings
        settings_of(EditSettings, settings["edit"]).check()
        from vecfit.fitting import losses
        losses.weighted(settings["optimize"]["loss"])
    if "retarget" in settings:
        from vecfit.editing.settings import RetargetSettings
        settings_of(RetargetSettings, settings["retarget"]).check()


def loop_settings(config: dict) -> Settings:
    """The [optimize] table of a config that ``resolve`` made (and checked) as the loop's
    Settings, its device resolved here: once a run, where the job runs (batch may hand
    jobs to other processes and machines)."""
    return Settings.of_checked(config["optimize"])


def output_precision(settings: dict) -> int | None:
    """[output] precision: the decimals of written coordinates, None for what the canvas
    needs (-1)."""
    value = settings["output"]["precision"]
    if value == -1:
        return None
    if not 0 <= value <= MAX_DECIMALS:
        raise VecfitError(f"output.precision must be 0 to {MAX_DECIMALS} decimals (or -1: what the canvas "
                          f"needs), not {value}")
    return value


def settings_of(cls, table: dict, **fixed):
    """A settings dataclass from a config table (plus ``fixed`` values, e.g. the seed)."""
    known = {f.name for f in dataclasses.fields(cls)}
    unknown = sorted(set(table) - known)
    if unknown:
        raise VecfitError(f"unknown {cls.__name__} fields: {', '.join(unknown)}")
    return cls(**{**table, **fixed})


def _drop_none(d: dict) -> dict:
    out = {}
    for k, v in d.items():
        if isinstance(v, dict):
            v = _drop_none(v)
            if v:
                out[k] = v
        elif v is not None:
            out[k] = v
    return out
