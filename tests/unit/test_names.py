"""Every list of names a user picks from is written once, in vecfit/names.py: the command
line's choices are those lists, the core accepts exactly the render modes and filters,
and the checks of the configs refuse a name outside them."""
import click
import pytest

from vecfit import _core, names
from vecfit.cli.commands import main
from vecfit.errors import VecfitError

# (command, option) -> the list its choices come from
CHOICES = {
    ("render", "mode"): names.MODES,
    ("render", "filter_"): names.FILTERS,
    ("batch", "mode"): names.JOBS,
    ("batch", "effort"): names.EFFORTS,
    ("batch", "style"): names.STYLES,
    ("batch", "output_format"): names.FORMATS,
    ("trace", "style"): names.STYLES,
    ("paint", "kind"): names.PAINT_KINDS,
    **{(command, option): values for command in ("refine", "trace", "paint")
       for option, values in (("mode", names.MODES), ("loss", names.LOSSES), ("effort", names.EFFORTS),
                              ("output_format", names.FORMATS), ("group_by", names.GROUP_BY))},
}


def _choices(command: str, option: str) -> tuple:
    (param,) = [p for p in main.commands[command].params if p.name == option]
    assert isinstance(param.type, click.Choice)
    return tuple(param.type.choices)


@pytest.mark.parametrize("command,option", sorted(CHOICES))
def test_the_command_lines_choices_are_the_names(command, option):
    assert _choices(command, option) == CHOICES[(command, option)]


def test_every_choice_of_the_command_line_is_a_list_of_names():
    """No command offers a Choice written out by hand."""
    lists = {v for k, v in vars(names).items() if k.isupper()}
    for name, command in main.commands.items():
        for param in command.params:
            if isinstance(param.type, click.Choice):
                assert tuple(param.type.choices) in lists, (name, param.name)


def test_the_core_takes_exactly_the_modes_and_filters():
    for mode in names.MODES:
        assert _core.RenderOptions(width=1, height=1, mode=mode).mode == mode
    for filt in names.FILTERS:
        assert _core.RenderOptions(width=1, height=1, filter=filt).filter == filt
    with pytest.raises(ValueError):
        _core.RenderOptions(width=1, height=1, mode="exact")
    with pytest.raises(ValueError):
        _core.RenderOptions(width=1, height=1, filter="lanczos")


def test_the_renderers_options_check_the_same_names():
    from vecfit.renderer.options import RenderOptions
    for mode in names.MODES:
        assert RenderOptions(1, 1, mode=mode).mode == mode
    for filt in names.FILTERS:
        assert RenderOptions(1, 1, filter=filt).filter == filt
    with pytest.raises(VecfitError, match="mode must be one of mc, analytic"):
        RenderOptions(1, 1, mode="exact")
    with pytest.raises(VecfitError, match="filter must be one of box, tent"):
        RenderOptions(1, 1, filter="lanczos")


def test_the_configs_refuse_a_name_outside_the_lists():
    from vecfit.fitting.settings import Settings, defaults
    from vecfit.jobs.config import resolve
    with pytest.raises(VecfitError, match="loss must be one of l2, l1, ssim, pyramid, not 'l3'"):
        Settings.from_config({**defaults("refine", "optimize"), "loss": "l3"})
    with pytest.raises(VecfitError, match="unknown effort 'fast' \\(known: quick, normal, best\\)"):
        resolve("refine", effort="fast")


def test_the_loop_implements_exactly_the_losses():
    from vecfit.fitting import losses
    assert tuple(losses.FUNCTIONS) == names.LOSSES
    assert set(losses.WEIGHTED) < set(names.LOSSES)


def test_the_package_and_the_jobs_agree():
    from vecfit.batch import plan
    from vecfit.jobs.protocol import JOB_MODULES
    assert tuple(JOB_MODULES) == names.JOBS == plan.MODES
    assert set(names.JOBS) <= set(__import__("vecfit").__all__)  # vecfit.trace(...), ...
