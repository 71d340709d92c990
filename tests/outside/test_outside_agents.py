"""Agents trained outside neurosym through its commands: the examples of examples/own_agent/
end to end on tiny budgets, the command-line forms that name them, and SB3 files that would
run code when unpickled."""

from __future__ import annotations

import base64
import io
import json
import pickle
import runpy
import sys
import zipfile
from pathlib import Path

import pytest

from neurosym.cli import main

pytest.importorskip("stable_baselines3")  # the dev extra installs it; `pip install neurosym[sb3]`

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "own_agent"
MY_AGENT = f"{EXAMPLES / 'my_agent.py'}:make_agent"
MY_RGW2_AGENT = f"{EXAMPLES / 'my_agent.py'}:make_rgw2_agent"
ENV = "MiniGrid-DoorKey-5x5-v0"
SHORT = ["--env-option", "max_steps=12"]


def _query(kb: Path, goal: str, *rules: str) -> list[dict]:
    from neurosym.prolog.knowledge_base import KnowledgeBase

    with KnowledgeBase(kb, rules=list(rules)) as base:
        return base.query(goal)


def _error(capsys: pytest.CaptureFixture[str], argv: list[str]) -> str:
    assert main(argv) == 1
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1
    return lines[0]


def test_the_torch_example_goes_through_extract_query_intervene_and_report(tmp_path: Path) -> None:
    out = tmp_path / "torch"
    assert main(["extract", "--checkpoint", MY_AGENT, "--episodes", "2", *SHORT, "--format",
                 "pl,parquet", "--out", str(out), "--quiet"]) == 0  # fmt: skip
    assert _query(out / "kb.pl", "kb_meta(module, M)")[0]["M"] == "outside_attention"
    heads = _query(out / "kb.pl", "head(H)", "relations")
    assert [row["H"] for row in heads] == [0, 1]
    agent_rows = _query(out / "kb.pl", "attention(0, 0, H, agent, K, W)")
    assert sorted(row["H"] for row in agent_rows) == [0, 1]  # one strongest key per head
    assert all(0.0 < row["W"] <= 1.0 for row in agent_rows)

    ablated = tmp_path / "ablate"  # intervene plays RGW and Box-World: the same network on rgw2
    assert main(["intervene", "--checkpoint", MY_RGW2_AGENT, "--no-levels", "--episodes", "2",
                 *SHORT, "--out", str(ablated)]) == 0  # fmt: skip
    kinds = _query(ablated / "kb.pl", "experiment(X, ablate(head(H)), _)")
    assert sorted((row["X"], row["H"]) for row in kinds) == [
        ("ablate_head_0", 0),
        ("ablate_head_1", 1),
    ]
    shifts = _query(ablated / "kb.pl", "effect(X, head_shift(H), V)")
    moved = {(row["X"], row["H"]) for row in shifts if row["V"] > 0.0}
    assert moved == {("ablate_head_0", 0), ("ablate_head_1", 1), ("ablate_heads", 0),
                     ("ablate_heads", 1)}  # each ablation moves its own heads and no other  # fmt: skip
    assert {row["X"] for row in _query(ablated / "kb.pl", "effect(X, kl, _)")} == {
        "ablate_head_0", "ablate_head_1", "ablate_heads"}  # fmt: skip

    assert main(["report", "--recording", str(out), "--quiet"]) == 0
    page = (out / "index.html").read_text()
    assert "outside_attention, 2 heads" in page

    # a recording naming Python code as its checkpoint: the page is built, the code never runs
    marker = tmp_path / "ran"
    evil = tmp_path / "evil.py"
    evil.write_text(f"open({str(marker)!r}, 'w').close()\ndef make_agent():\n    pass\n")
    meta_file = out / "recording" / "meta.json"
    for name in (f"{evil}:make_agent", str(evil)):
        meta = json.loads(meta_file.read_text())
        meta["meta"]["checkpoint"] = name
        meta_file.unlink()  # published files are read-only links into the store
        meta_file.write_text(json.dumps(meta))
        assert main(["report", "--recording", str(out), "--quiet"]) == 0
        assert not marker.exists()
        assert "evil.py" in (out / "index.html").read_text()  # the page names it, nothing more


@pytest.fixture(scope="module")
def sb3_model(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The SB3 example's model (examples/own_agent/sb3_agent.py, 256 steps), trained once."""
    model = tmp_path_factory.mktemp("sb3") / "ppo.zip"
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(sys, "argv", ["sb3_agent.py", "--steps", "256", "--out", str(model)])
        runpy.run_path(str(EXAMPLES / "sb3_agent.py"), run_name="__main__")
    return model


def test_the_sb3_example_trains_and_its_zip_is_extracted_and_queried(
    sb3_model: Path, tmp_path: Path
) -> None:
    model = sb3_model
    out = tmp_path / "sb3"
    assert main(["extract", "--checkpoint", str(model), "--env", ENV, "--episodes", "2", *SHORT,
                 "--out", str(out), "--quiet"]) == 0  # fmt: skip
    kb = out / "kb.pl"
    assert _query(kb, "kb_meta(module, M)")[0]["M"] == "outside"
    episodes = _query(kb, "episode(E, S, R, O)")
    assert [row["E"] for row in episodes] == [0, 1]
    steps = _query(kb, "findall(A, step(0, _, A, _), As)")[0]["As"]
    assert len(steps) == episodes[0]["S"] and set(steps) <= {
        "left", "right", "forward", "pickup", "drop", "toggle", "done"}  # fmt: skip
    no_attention = "aggregate_all(count, attention(_, _, _, _, _, _), N)"
    assert _query(kb, no_attention)[0]["N"] == 0  # no hook points named
    assert main(["report", "--recording", str(out), "--quiet"]) == 0
    assert "stable-baselines3 PPO" in (out / "index.html").read_text()


def test_an_sb3_zip_teaches_as_a_dagger_teacher(sb3_model: Path) -> None:
    """--algo imitate --set teacher=ppo.zip: its labels are its policy's probabilities."""
    import numpy as np
    import torch

    from neurosym.agent.agent import load_agent
    from neurosym.agent.learners.teacher import load_teacher
    from neurosym.envs import make_batched

    model = sb3_model
    agent = load_agent(str(model), play_env=ENV)
    teacher = load_teacher(str(model), ENV, agent.config.obs_shape, agent.config.n_actions)
    venv = make_batched(ENV, 3, seed=1)
    obs, _ = venv.reset(seed=1)
    probs, values = teacher.labels(obs)
    assert probs.shape == (3, agent.config.n_actions) and values.shape == (3,)
    assert probs.sum(1) == pytest.approx(np.ones(3), abs=1e-5)
    with torch.no_grad():
        logits = agent.model(torch.from_numpy(obs))[0]
    assert probs == pytest.approx(torch.softmax(logits, -1).numpy(), abs=1e-6)


@pytest.mark.parametrize(
    ("checkpoint", "message"),
    [
        ("{ex}/my_agent.py", "{ex}/my_agent.py is Python code: name the function in it that "
         "returns the agent, --checkpoint {ex}/my_agent.py:make_agent"),
        ("{ex}/my_agent.py:9", "--checkpoint {ex}/my_agent.py:9: '9' is not a function name; "
         "expected FILE.py:FUNCTION (make_agent, say)"),
        ("{ex}/my_agent.py:nope", "{ex}/my_agent.py has no function 'nope'; its functions: "
         "CellAttentionNet, make_agent, make_rgw2_agent"),
        ("{ex}/absent.py:make_agent", "--checkpoint {ex}/absent.py:make_agent: no such file {ex}/absent.py"),
        ("{tmp}/absent.zip", "Stable-Baselines3 model not found: {tmp}/absent.zip"),
    ],
)  # fmt: skip
def test_a_bad_agent_name_is_one_line_saying_what_would_be_right(
    checkpoint: str, message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    fill = {"ex": str(EXAMPLES), "tmp": str(tmp_path)}
    line = _error(
        capsys, ["extract", "--checkpoint", checkpoint.format(**fill), "--out", str(tmp_path / "o")]
    )
    assert line == f"neurosym extract: error: {message.format(**fill)}"


def test_a_user_function_that_fails_or_returns_no_agent_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    user = tmp_path / "agent.py"
    user.write_text("def broken():\n    return {}['weights']\n\ndef plain():\n    return 3\n\n"
                    "def wrong_layer():\n    import torch\n    from neurosym.outside import TorchAgent\n"
                    "    return TorchAgent(torch.nn.Linear(2, 2), env='rgw2', attention='attn')\n")  # fmt: skip
    out = ["--out", str(tmp_path / "o")]
    assert _error(capsys, ["extract", "--checkpoint", f"{user}:broken", *out]) == (
        f"neurosym extract: error: {user}:broken() raised KeyError: 'weights' (agent.py line 2)"
    )
    assert _error(capsys, ["extract", "--checkpoint", f"{user}:plain", *out]) == (
        f"neurosym extract: error: {user}:plain() returned a int; it must return "
        "neurosym.outside.TorchAgent(...) or neurosym.outside.sb3_agent(...)"
    )
    assert _error(capsys, ["extract", "--checkpoint", f"{user}:wrong_layer", *out]) == (
        "neurosym extract: error: Linear has no submodule 'attn'; its attention modules: none"
    )


def _sb3_zip(path: Path, policy_kwargs: object) -> Path:
    """A minimal SB3-shaped file whose policy_kwargs entry is ``policy_kwargs`` pickled."""
    from stable_baselines3.common.policies import ActorCriticPolicy

    policy_class = base64.b64encode(pickle.dumps(ActorCriticPolicy)).decode()
    data = {
        "policy_class": {":type:": "<class 'abc.ABCMeta'>", ":serialized:": policy_class},
        "policy_kwargs": {":type:": "<class 'dict'>",
                          ":serialized:": base64.b64encode(pickle.dumps(policy_kwargs)).decode()},
        "observation_space": {"_shape": [9, 10, 10], "dtype": "uint8"},
        "action_space": {"n": "4"},
    }  # fmt: skip
    weights = io.BytesIO()
    import torch

    torch.save({"w": torch.zeros(2)}, weights)
    with zipfile.ZipFile(path, "w") as z:
        z.writestr("data", json.dumps(data))
        z.writestr("policy.pth", weights.getvalue())
    return path


class _RunsCode:
    def __reduce__(self) -> tuple:
        return (print, ("this ran",))


def test_an_sb3_file_that_would_run_code_is_refused_and_nothing_runs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    evil = _sb3_zip(tmp_path / "evil.zip", {"net_arch": _RunsCode()})
    line = _error(
        capsys,
        ["extract", "--checkpoint", str(evil), "--env", "rgw2", "--out", str(tmp_path / "o")],
    )
    assert line == (
        f"neurosym extract: error: {evil}'s policy_kwargs builds objects when unpickled (REDUCE); "
        "neurosym reads only names, numbers, strings, lists and dicts from a model file"
    )
    assert "this ran" not in capsys.readouterr().out
    custom = _sb3_zip(tmp_path / "custom.zip", {"features_extractor_class": _RunsCode})
    line = _error(
        capsys,
        ["extract", "--checkpoint", str(custom), "--env", "rgw2", "--out", str(tmp_path / "o")],
    )
    assert line.startswith(
        f"neurosym extract: error: {custom}'s policy_kwargs names test_outside_agents._RunsCode, "
        "which neurosym does not load from a file"
    )
    assert line.endswith("name it with --checkpoint FILE.py:FUNCTION (neurosym.outside.sb3_agent)")


def test_an_sb3_policy_with_an_attention_extractor_gives_attention_facts_and_ablates() -> None:
    """The user's file route for SB3: a policy whose features extractor holds an
    nn.MultiheadAttention over the cells, named by its dotted path."""
    import numpy as np
    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
    from torch import nn

    from neurosym.envs import make
    from neurosym.meaning.features import ablate_heads, head_vectors
    from neurosym.outside import sb3_agent
    from neurosym.record.recorder import record

    class CellAttention(BaseFeaturesExtractor):
        def __init__(self, space, width: int = 16) -> None:
            super().__init__(space, features_dim=width)
            self.embed = nn.Conv2d(space.shape[0], width, 1)
            self.attn = nn.MultiheadAttention(width, 2, batch_first=True)

        def forward(self, obs: torch.Tensor) -> torch.Tensor:
            x = self.embed(obs).flatten(2).transpose(1, 2)
            return self.attn(x, x, x)[0].amax(dim=1)

    torch.manual_seed(0)
    model = PPO("MlpPolicy", make("rgw2"), n_steps=8, batch_size=8, device="cpu",
                policy_kwargs={"features_extractor_class": CellAttention})  # fmt: skip
    agent = sb3_agent(
        model, "rgw2", attention="features_extractor.attn", env_kwargs={"max_steps": 5}
    )
    rec = record(agent, episodes=1)
    assert rec.meta["module"] == "outside_attention" and rec.meta["heads"] == 2
    assert set(rec.attention["head"]) == {0, 1} and len(rec.attention) > 0
    obs = np.stack([make("rgw2").reset(seed=s)[0] for s in range(3)])
    plain, probs = head_vectors(agent.model, obs)  # (3, 2, 8): each head's values, pooled
    with ablate_heads(agent.model, {0: torch.zeros(100, 8)}):
        ablated, ablated_probs = head_vectors(agent.model, obs)
    np.testing.assert_array_equal(ablated[:, 0], 0.0)
    np.testing.assert_array_equal(ablated[:, 1], plain[:, 1])
    assert not np.allclose(ablated_probs, probs)


def test_an_sb3_model_without_heads_goes_through_intervene_with_no_ablations(
    tmp_path: Path,
) -> None:
    from stable_baselines3 import PPO

    from neurosym.envs import make

    model = tmp_path / "ppo_rgw2.zip"
    PPO("MlpPolicy", make("rgw2"), n_steps=8, batch_size=8, seed=0, device="cpu").save(model)
    out = tmp_path / "intervene"
    argv = ["intervene", "--checkpoint", str(model), "--env", "rgw2", "--episodes", "1"]
    assert main([*argv, "--out", str(out)]) == 0
    kinds = [row["X"] for row in _query(out / "kb.pl", "experiment(X, _, _)")]
    assert kinds == ["baseline", "remove_sword", "remove_enemy", "move_enemy", "move_sword",
                     "swap_sword_enemy"]  # no heads: no ablation experiments  # fmt: skip
