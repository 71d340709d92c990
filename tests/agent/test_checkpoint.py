"""Checkpoints: round trip, safe loading, and one clear line for every bad file."""

from __future__ import annotations

import os
import pickle
from pathlib import Path

import numpy as np
import pytest
import torch

from neurosym.agent.agent import load_agent
from neurosym.agent.checkpoint import FORMAT, read_checkpoint, save_checkpoint
from neurosym.agent.config import ModelConfig, TrainConfig
from neurosym.agent.networks.introspection import PrediNetIntrospection
from neurosym.agent.networks.model import ActorCritic
from neurosym.errors import CheckpointError

CONFIG = ModelConfig.for_family("rgw", "predinet", (9, 10, 10))


def write(path: Path, config: ModelConfig = CONFIG, **kw) -> ActorCritic:
    torch.manual_seed(0)
    model = ActorCritic(config)
    save_checkpoint(
        path,
        model=model,
        config=config,
        env_name=kw.pop("env_name", "rgw2"),
        env_kwargs={"max_steps": 100},
        train_config=TrainConfig.for_family("rgw"),
        frames=1234,
        episodes=12,
        metrics={"wall_s": 1.5, "greedy_return": None},
        command="neurosym train --env rgw2 --module predinet --out runs/x",
        **kw,
    )
    return model


def error_of(path: Path, **kw) -> str:
    with pytest.raises(CheckpointError) as info:
        load_agent(path, **kw)
    message = str(info.value)
    assert "\n" not in message, message
    return message


def test_round_trip_and_act(tmp_path: Path) -> None:
    path = tmp_path / "a.pt"
    model = write(path)
    assert [p.name for p in tmp_path.iterdir()] == ["a.pt"]  # no temp file left behind
    raw = torch.load(path, weights_only=True)
    assert raw["format"] == FORMAT and raw["format_version"] == 1 and raw["frames"] == 1234
    assert raw["model_config"] == CONFIG.to_dict() and raw["env"] == "rgw2"
    assert raw["command"].startswith("neurosym train")
    agent = load_agent(path)
    assert (
        agent.config == CONFIG
        and agent.env_name == "rgw2"
        and agent.env_kwargs == {"max_steps": 100}
    )
    assert agent.meta["frames"] == 1234 and agent.meta["metrics"]["wall_s"] == 1.5
    assert not agent.model.training
    for name, tensor in model.state_dict().items():
        assert torch.equal(agent.model.state_dict()[name], tensor), name
    obs = np.random.default_rng(0).integers(0, 2, (5, 9, 10, 10)).astype(np.uint8)
    actions, intro = agent.act(obs)
    logits, _ = model(torch.from_numpy(obs))
    assert actions.shape == (5,) and np.array_equal(actions, logits.argmax(-1).numpy())
    actions_i, intro = agent.act(obs, introspect=True)
    assert np.array_equal(actions, actions_i)
    assert isinstance(intro, PrediNetIntrospection) and isinstance(intro.attention1, np.ndarray)
    assert intro.r_vectors().shape == (5, 4, 12)
    one, _ = agent.act(obs[0])  # a single observation is a batch of one
    assert one.shape == (1,) and one[0] == actions[0]
    g1, g2 = torch.Generator().manual_seed(3), torch.Generator().manual_seed(3)
    assert np.array_equal(
        agent.act(obs, greedy=False, generator=g1)[0], agent.act(obs, greedy=False, generator=g2)[0]
    )


def test_overwrite_is_atomic_replacement(tmp_path: Path) -> None:
    path = tmp_path / "a.pt"
    write(path)
    write(path, env_name="rgw1")
    assert read_checkpoint(path)["env"] == "rgw1"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.pt"]


def test_optimizer_state_round_trips_or_is_left_out(tmp_path: Path) -> None:
    from neurosym.agent.learners.optimizers import SharedRMSprop

    model = ActorCritic(CONFIG)
    opt = SharedRMSprop(model.parameters(), lr=1e-3, alpha=0.99, eps=0.1)
    write(tmp_path / "a.pt", optimizer_state=opt.state_dict())
    saved = read_checkpoint(tmp_path / "a.pt")["optimizer"]
    assert saved["param_groups"][0]["eps"] == 0.1 and len(saved["state"]) == len(
        list(model.parameters())
    )
    write(tmp_path / "b.pt")  # slim: no optimizer state
    assert read_checkpoint(tmp_path / "b.pt")["optimizer"] is None


def test_missing_file(tmp_path: Path) -> None:
    assert error_of(tmp_path / "nope.pt") == f"checkpoint not found: {tmp_path / 'nope.pt'}"
    assert "is not a file" in error_of(tmp_path)


def test_truncated_file(tmp_path: Path) -> None:
    path = tmp_path / "a.pt"
    write(path)
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    assert "truncated, corrupt or not a torch checkpoint" in error_of(path)
    path.write_bytes(b"")
    assert "cannot read" in error_of(path)


def test_text_file(tmp_path: Path) -> None:
    path = tmp_path / "notes.pt"
    path.write_text("hello, these are my notes\nline two\n")
    assert error_of(path).startswith(f"cannot read {path}")


def test_plain_state_dict_is_foreign(tmp_path: Path) -> None:
    path = tmp_path / "sd.pt"
    torch.save(ActorCritic(CONFIG).state_dict(), path)
    assert "plain torch state dict, not a neurosym checkpoint" in error_of(path)
    torch.save({"format": "something-else"}, path)
    assert "not a neurosym checkpoint (format 'something-else')" in error_of(path)
    torch.save([1, 2, 3], path)
    assert "not a neurosym checkpoint (it holds a list)" in error_of(path)


class _Exploit:
    """Unpickling this would create the marker file."""

    def __init__(self, marker: Path) -> None:
        self.marker = marker

    def __reduce__(self):
        return (Path.touch, (self.marker,))


@pytest.mark.filterwarnings("ignore:Detected pickle protocol")
@pytest.mark.parametrize("how", ["pickle", "torch.save"])
def test_malicious_pickle_runs_no_code(tmp_path: Path, how: str) -> None:
    marker = tmp_path / "pwned"
    path = tmp_path / "evil.pt"
    payload = {"format": FORMAT, "format_version": 1, "state_dict": _Exploit(marker)}
    if how == "pickle":
        path.write_bytes(pickle.dumps(payload))
    else:
        torch.save(payload, path)
    # the payload really is armed: unpickling it unsafely creates the marker
    pickle.loads(pickle.dumps(_Exploit(tmp_path / "armed")))
    assert (tmp_path / "armed").exists()
    message = error_of(path)
    assert not marker.exists()
    assert (
        message.startswith(f"refused {path}: it holds pickled Python objects")
        and "nothing in it was run" in message
    )


def test_damaged_fields_and_newer_format(tmp_path: Path) -> None:
    path = tmp_path / "a.pt"
    write(path)
    raw = torch.load(path, weights_only=True)
    torch.save({**raw, "format_version": 99}, path)
    assert "format version 99; this neurosym reads version 1" in error_of(path)
    torch.save({**raw, "frames": "many"}, path)
    assert "'frames' is missing or has the wrong type" in error_of(path)
    torch.save({**raw, "model_config": {**raw["model_config"], "module": "lstm"}}, path)
    assert "bad model config: unknown module 'lstm'" in error_of(path)
    state = dict(raw["state_dict"])
    state["policy.weight"] = torch.zeros(7, 64)
    torch.save({**raw, "state_dict": state}, path)
    assert "the weights do not fit its model config" in error_of(path)


def test_model_config_mismatch(tmp_path: Path) -> None:
    path = tmp_path / "a.pt"
    write(path)
    other = ModelConfig.for_family("rgw", "mhdpa", (9, 10, 10), heads=2)
    message = error_of(path, config=other)
    assert (
        message
        == f"{path} has a different model config: module 'predinet' (asked for 'mhdpa'); heads 4 (asked for 2)"
    )


def test_checkpoint_for_another_env(tmp_path: Path) -> None:
    """Any env of its family with its observation shape; another family or shape: one line."""
    path = tmp_path / "a.pt"
    write(path)
    assert error_of(path, env="bw1") == (
        f"{path} was trained on rgw2 (rgw family, observations (9, 10, 10)); "
        "bw1 is a boxworld environment: pick one of rgw1, rgw2, rgw-random"
    )
    assert load_agent(path, env="neurosym/RGW2-v0").env_name == "rgw2"
    assert load_agent(path, env="rgw1").env_name == "rgw2"  # runs there; trained on rgw2
    assert load_agent(path, env="rgw-random").env_name == "rgw2"


def test_save_refuses_objects(tmp_path: Path) -> None:
    from neurosym.errors import ConfigError

    with pytest.raises(ConfigError, match="only tensors and plain values"):
        save_checkpoint(
            tmp_path / "a.pt",
            model=ActorCritic(CONFIG),
            config=CONFIG,
            env_name="rgw2",
            metrics={"when": object()},
        )
    assert not os.listdir(tmp_path)


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (
            {"hidden_sizes": [10**6, 10**6]},
            "has a bad model config: hidden_sizes must be 1 to 8 entries, each an integer in "
            "[1, 8192], got 1000000,1000000",
        ),
        ({"heads": 10**9}, "has a bad model config: heads must be an integer in [1, 64], got 1000000000"),
        (
            {"hidden_sizes": [8192, 8192]},
            "is damaged: its model config has hidden_sizes (8192, 8192), larger than any dimension "
            "of its weights (2600)",
        ),
    ],
)
def test_a_config_out_of_range_or_far_larger_than_its_weights_is_refused_before_building(
    tmp_path: Path, neurosym_main, edit: dict, message: str
) -> None:
    """Out of a setting's range: the config's own line; in range but larger than every weight
    dimension (a damaged file): refused before the model is built."""
    path = tmp_path / "a.pt"
    write(path)
    raw = torch.load(path, weights_only=True)
    torch.save({**raw, "model_config": {**raw["model_config"], **edit}}, path)
    expected = f"checkpoint {path} {message}"
    assert error_of(path) == expected
    proc = neurosym_main("eval", "--checkpoint", path, "--episodes", 1)
    assert (proc.returncode, proc.stderr) == (1, f"neurosym eval: error: {expected}\n")


def test_a_model_that_cannot_be_allocated_is_one_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import neurosym.agent.checkpoint as checkpoint

    def no_memory(config: ModelConfig) -> ActorCritic:
        raise RuntimeError(
            "[enforce fail at alloc_cpu.cpp:117] data. DefaultCPUAllocator: not enough memory: "
            "you tried to allocate 416000000000 bytes.\nmore detail"
        )

    path = tmp_path / "a.pt"
    write(path)
    monkeypatch.setattr(checkpoint, "ActorCritic", no_memory)
    assert error_of(path) == (
        f"{path}: its model config does not fit in memory ([enforce fail at alloc_cpu.cpp:117] "
        "data. DefaultCPUAllocator: not enough memory: you tried to allocate 416000000000 bytes.)"
    )


def test_a_checkpoint_edited_to_another_env_names_the_file(tmp_path: Path, neurosym_main) -> None:
    path = tmp_path / "a.pt"
    write(path)
    raw = torch.load(path, weights_only=True)
    torch.save({**raw, "env": "bw1", "env_kwargs": {}}, path)
    expected = (
        f"checkpoint {path} is damaged: its env bw1 gives observations (3, 14, 14), "
        "its model takes (9, 10, 10)"
    )
    assert error_of(path) == expected
    for command, *more in (("eval",), ("extract", "--out", tmp_path / "o")):
        proc = neurosym_main(command, "--checkpoint", path, "--episodes", 1, *more)
        assert (proc.returncode, proc.stderr) == (1, f"neurosym {command}: error: {expected}\n")
    torch.save({**raw, "env": "rgw9"}, path)
    assert error_of(path).startswith(f"checkpoint {path} names an env this neurosym lacks: ")
    torch.save({**raw, "env_kwargs": {"max_steps": 100, "map": str(tmp_path / "moved.txt")}}, path)
    assert load_agent(path).env_kwargs["map"].endswith("moved.txt")  # checked where it is played


def test_a_checkpoint_that_cannot_be_opened_is_one_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "a.pt"
    write(path)

    def refuse(self: Path, *args: object, **kwargs: object) -> None:
        raise PermissionError(13, "Permission denied", str(self))

    monkeypatch.setattr(Path, "open", refuse)
    assert error_of(path) == f"cannot read {path}: Permission denied"


def test_a_small_model_on_a_small_map_loads_whatever_its_unused_sizes(tmp_path: Path) -> None:
    """PrediNet has no value_size layer: its default (64) may exceed every weight of a tiny net."""
    config = ModelConfig.for_family(
        "rgw", "predinet", (9, 1, 4), heads=2, key_size=4, relations=3,
        conv_channels=(4, 8), hidden_sizes=(16,),
    )  # fmt: skip
    path = tmp_path / "tiny.pt"
    save_checkpoint(path, model=ActorCritic(config), config=config, env_name="rgw2",
                    env_kwargs={"map": "A.ST\n"})  # fmt: skip
    agent = load_agent(path)
    assert (
        agent.config.value_size == 64 > max(max(t.shape) for t in agent.model.state_dict().values())
    )


def shared_lists(levels: int) -> list:
    """``[l, l]`` nested ``levels`` times: 2**levels leaves when walked, a few bytes pickled."""
    out: list = [0]
    for _ in range(levels):
        out = [out, out]
    return out


@pytest.mark.parametrize(
    ("entry", "value", "message"),
    [
        ("card", shared_lists(40), "its 'card' is nested more than 20 levels deep"),
        ("env_kwargs", {"map": shared_lists(40)}, "its 'env_kwargs' is nested more than 20 levels"),
        ("card", shared_lists(15), "its 'card' is too large: more than 10,000 values (counting "
         "every place a shared one occurs"),
        ("metrics", {"names": ["x" * 600_000] * 2}, "its 'metrics' is too large: more than "
         "1,000,000 characters of text"),
        ("metrics", {"loss": torch.zeros(2)}, "its 'metrics' holds a value of type Tensor; plain metadata holds "
         "only str, int, float, bool, None, lists and dicts"),
        ("card", {1: "a"}, "its 'card' has a key of type int (plain metadata: str)"),
    ],
)  # fmt: skip
def test_metadata_is_bounded_plain_data(
    tmp_path: Path, entry: str, value: object, message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """A card, env options or metrics that expand when walked (shared lists: accepted by
    torch.load(weights_only=True)) are refused once, where the file is read, in one line; so
    `neurosym agents` skips the file and `neurosym report` stops at once."""
    from neurosym.cli import main

    path = tmp_path / "a.pt"
    write(path)
    torch.save({**torch.load(path, weights_only=True), entry: value}, path)
    assert error_of(path).startswith(f"checkpoint {path}: {message}")
    assert main(["agents", "--dir", str(tmp_path), "--json"]) == 0
    out, err = capsys.readouterr()
    assert out == "[]\n" and err.startswith(f"neurosym agents: skipped a.pt: checkpoint {path}: ")
    assert err.count("\n") == 1
    assert main(["report", "--checkpoint", str(path), "--out", str(tmp_path / "page")]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"neurosym report: error: checkpoint {path}: {message}")
    assert err.count("\n") == 1 and not (tmp_path / "page" / "index.html").exists()


def test_negative_counts_are_refused(tmp_path: Path) -> None:
    path = tmp_path / "a.pt"
    write(path)
    torch.save({**torch.load(path, weights_only=True), "frames": -5}, path)
    assert error_of(path) == (
        f"checkpoint {path} is damaged: 'frames' is -5; it counts, so it is 0 or more"
    )


@pytest.mark.parametrize(
    ("card", "why"),
    [
        ({"role": "r", "eval_command": "e", "held_out": {"greedy": {"success_rate": 0.5}}},
         "the card in a.pt: held_out lacks its 'sampled' figures (held_out.sampled must be a dict)"),
        ([1, 2], "the card in a.pt is of type list, not a dict"),
        ({"role": 3, "eval_command": "e", "held_out": {}}, "the card in a.pt: role is of type int, not text"),
    ],
)  # fmt: skip
def test_agents_lists_an_agent_with_a_malformed_card_with_its_figures_blank(
    tmp_path: Path, card: object, why: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """Its weights still play, so it is listed; its held-out cell and role are blank, and one
    line names the field that is wrong."""
    import json

    from neurosym.cli import main

    path = tmp_path / "a.pt"
    write(path)
    torch.save({**torch.load(path, weights_only=True), "card": card}, path)
    assert main(["agents", "--dir", str(tmp_path), "--json"]) == 0
    out, err = capsys.readouterr()
    (agent,) = json.loads(out)
    assert agent["card"] is None and agent["card_error"] == why
    assert err == f"neurosym agents: {why}; its held-out figures are left blank\n"
    assert main(["agents", "--dir", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    row = next(line for line in out.splitlines() if line.split()[:1] == ["a"])
    assert row.split() == ["a", "rgw2", "predinet", "a3c", "1", "k", "-", "-"]
