"""``--env-option`` values typed by the env's options; render-only options and bad values refused."""

from __future__ import annotations

import warnings

import pytest

from neurosym.cli import parse_env_options
from neurosym.envs import make
from neurosym.envs.options import OptionType, parse_value
from neurosym.envs.registration import ENTRIES, option_types
from neurosym.errors import ConfigError


@pytest.mark.parametrize(
    ("items", "env", "expected"),
    [
        (["classic=false"], "rgw2", {"classic": False}),
        (["classic=no", "max_steps=50"], "rgw2", {"classic": False, "max_steps": 50}),
        (["classic=True"], None, {"classic": True}),
        (["max_steps=none"], "rgw1", {"max_steps": None}),
        (["guarded_share=1", "num_mountains=12"], "rgw-random", {"guarded_share": 1.0, "num_mountains": 12}),
        (["edit=remove_sword"], "rgw-random", {"edit": "remove_sword"}),
        (["map=my_map.txt"], "rgw2", {"map": "my_map.txt"}),
        (["obs_mode=grey"], None, {"obs_mode": "grey"}),
        (["solution_length=2"], "bw1", {"solution_length": 2}),
    ],
)  # fmt: skip
def test_values_take_the_option_type(items: list[str], env: str | None, expected: dict) -> None:
    got = parse_env_options(items, env)
    assert got == expected
    assert all(type(got[k]) is type(v) for k, v in expected.items())


@pytest.mark.parametrize(
    ("items", "env", "message"),
    [
        (["classic=maybe"], "rgw2", "--env-option classic='maybe': classic takes true or false"),
        (["classic=maybe"], None, "--env-option classic='maybe': classic takes true or false"),
        (["max_steps=1.5"], "rgw2", "--env-option max_steps='1.5': max_steps takes an integer or none"),
        (["max_steps=none"], "bw1", "--env-option max_steps='none': max_steps takes an integer"),
        (["guarded_share=nan"], "rgw-random", "guarded_share takes a finite number"),
        (["num_mountains=12"], "rgw2", "unknown option 'num_mountains' for rgw2; expected one of map, classic"),
        (["render_mode=human"], "rgw2", "--env-option render_mode: not an option here"),
        (["render_mode=human"], None, "--env-option render_mode: not an option here"),
        (["tile_size=8"], "bw1", "--env-option tile_size: not an option here"),
        (["classic=true", "classic=false"], "rgw2", "--env-option classic is given twice"),
    ],
)  # fmt: skip
def test_bad_values_are_refused_naming_option_value_and_type(
    items: list[str], env: str | None, message: str
) -> None:
    with pytest.raises(ConfigError) as err:
        parse_env_options(items, env)
    assert message in str(err.value) and "\n" not in str(err.value)


def test_make_refuses_a_value_of_the_wrong_type() -> None:
    """``classic="false"`` is a true value: refused, not played as classic rules."""
    with pytest.raises(
        ConfigError, match=r"option classic='false' for rgw2: classic takes true or false"
    ):
        make("rgw2", classic="false")
    with pytest.raises(ConfigError, match=r"num_mountains takes an integer"):
        make("rgw-random", num_mountains="12")
    make("rgw2", classic=False, max_steps=None).close()


def test_make_refuses_an_unknown_render_mode_without_gymnasium_warning() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # gymnasium's render-mode warning would fail here
        with pytest.raises(
            ConfigError, match=r"render_mode 'human' is not one of rgw2's: rgb_array, ansi"
        ):
            make("rgw2", render_mode="human")
        with pytest.raises(ConfigError, match=r"render_mode 'human' is not one of bw1's"):
            make("bw1", render_mode="human")


def test_every_option_is_typed_and_one_name_one_type() -> None:
    """Options of the same name have one kind across envs (typing by name alone, as train does)."""
    kinds: dict[str, set[str]] = {}
    for e in ENTRIES:
        for name, option in option_types(e.short).items():
            assert option.kind != "any", f"{e.short}: option {name} has no type"
            kinds.setdefault(name, set()).add(option.kind)
    assert {n: k for n, k in kinds.items() if len(k) > 1} == {}


def test_literal_choices() -> None:
    option = OptionType("str", choices=("a", "b"))
    assert parse_value(option, "b") == "b"
    with pytest.raises(ValueError, match="one of a, b"):
        parse_value(option, "c")


def test_eval_plays_classic_false_as_false(run_neurosym) -> None:  # noqa: ANN001
    import json

    from builders import REPO

    proc = run_neurosym(
        "eval", "--checkpoint", REPO / "checkpoints" / "rgw2-predinet.pt", "--episodes", 1,
        "--json", "--env-option", "classic=false",
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["env_kwargs"] == {"classic": False}
    bad = run_neurosym(
        "eval", "--checkpoint", REPO / "checkpoints" / "rgw2-predinet.pt",
        "--env-option", "render_mode=human",
    )  # fmt: skip
    assert bad.returncode == 1 and len(bad.stderr.strip().splitlines()) == 1, bad.stderr
    assert "render_mode: not an option here" in bad.stderr and "WARN" not in bad.stderr
