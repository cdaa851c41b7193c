"""One path for settings: the packaged files are merged by the same checked merge as the
user's file and the options (vecfit.io.configs.merge), the defaults every settings class
starts from are what a command resolves to, and [optimize] is typed whole by Settings:
a key it does not know is an error naming the file and the key, never dropped."""
import pytest

from vecfit.errors import VecfitError
from vecfit.fitting.settings import Settings
from vecfit.io import configs
from vecfit.jobs import config
from vecfit.names import JOBS


def test_one_merge():
    assert config.merge is configs.merge


@pytest.mark.parametrize("command", JOBS)
def test_the_defaults_are_what_a_command_resolves_to(command):
    resolved = config.resolve(command)
    for table in resolved:
        if table != "effort":
            assert configs.defaults(command, table) == resolved[table], table


def test_the_packaged_tables_are_checked_as_a_users_file_is(monkeypatch, tmp_path):
    """A packaged file that sets a key refine.toml does not have is refused, naming it."""
    read = configs.read_toml

    def with_typo(path):
        out = read(path)
        if str(path).endswith("trace.toml"):
            out.setdefault("optimize", {})["iteratons"] = 3
        return out

    configs.packaged.cache_clear()
    monkeypatch.setattr(configs, "read_toml", with_typo)
    try:
        with pytest.raises(VecfitError, match=r"configs/trace.toml: unknown setting 'optimize.iteratons'"):
            configs.defaults("trace", "trace")
    finally:
        monkeypatch.undo()
        configs.packaged.cache_clear()


def test_an_optimize_key_settings_does_not_type_is_an_error_naming_the_file(monkeypatch):
    """The schema is refine.toml's [optimize]; a key there that Settings lacks would once have
    been dropped silently (and read raw by the job)."""
    read = configs.read_toml

    def with_extra(path):
        out = read(path)
        if str(path).endswith("refine.toml"):
            out["optimize"]["new_knob"] = 1
        return out

    configs.packaged.cache_clear()
    monkeypatch.setattr(configs, "read_toml", with_extra)
    try:
        with pytest.raises(VecfitError, match=r"^configs/refine.toml: unknown setting 'optimize.new_knob'"):
            config.resolve("refine")
    finally:
        monkeypatch.undo()
        configs.packaged.cache_clear()
    table = configs.defaults("refine", "optimize")
    with pytest.raises(VecfitError, match=r"^my.toml: unknown setting 'optimize.max_sise'"):
        Settings.from_config({**table, "max_sise": 3}, source="my.toml")
    del table["eval_samples"]
    with pytest.raises(VecfitError, match=r"missing setting 'optimize.eval_samples'"):
        Settings.from_config(table)


def test_the_jobs_keys_of_optimize_are_typed_and_checked(tmp_path):
    s = Settings.defaults()
    assert (s.max_size, s.background, s.eval_samples, s.palette) == (1024, "auto", 4, "")
    for text, message in [("max_size = -1", "max_size must be 0"), ("eval_samples = 0", "eval_samples must be at least 1"),
                          ('background = "#ff000080"', "background must be opaque"),
                          ('background = "mauve-ish"', "background"), ("max_size = 1.5", "max_size must be int")]:
        path = tmp_path / "c.toml"
        path.write_text(f"[optimize]\n{text}\n")
        with pytest.raises(VecfitError, match=message):
            config.resolve("refine", config_file=path)
    assert config.resolve("refine", overrides={"optimize": {"max_size": 0}})["optimize"]["max_size"] == 0


def test_the_cached_defaults_are_not_shared(tmp_path):
    a = config.resolve("trace", effort="quick")
    a["optimize"]["lr"]["points"] = -5.0
    a["trace"]["paths"] = -1
    assert config.resolve("trace", effort="quick") != a
    assert configs.defaults("trace", "optimize")["lr"]["points"] >= 0
