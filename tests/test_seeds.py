"""``--seed``: every command that plays episodes takes seeds whose episodes fit in 63 bits."""

from __future__ import annotations

from pathlib import Path

import pytest

from neurosym.errors import ConfigError
from neurosym.seeds import MAX_SEED, check_seed

REPO = Path(__file__).resolve().parents[1]
CHECKPOINT = REPO / "checkpoints" / "rgw2-predinet.pt"


def test_the_range_depends_on_the_number_of_episodes() -> None:
    assert check_seed(MAX_SEED) == MAX_SEED
    assert check_seed(MAX_SEED - 9, episodes=10) == MAX_SEED - 9
    with pytest.raises(ConfigError) as err:
        check_seed(MAX_SEED - 8, episodes=10)
    assert str(err.value) == (
        "--seed must be an integer from 0 to 9223372036854775798 with 10 episodes "
        "(episode k plays seed SEED + k, at most 2**63 - 1), got 9223372036854775799"
    )
    with pytest.raises(ConfigError) as err:
        check_seed(0, episodes=10**20)
    assert str(err.value) == (
        "--episodes must be at most 2**63 (one seed each, at most 2**63 - 1), "
        "got 100000000000000000000"
    )
    for bad in (-1, 2**64, True, 1.0):
        with pytest.raises(ConfigError, match="--seed must be an integer from 0 to "):
            check_seed(bad)


@pytest.mark.parametrize("command", ["eval", "extract", "probe", "intervene"])
@pytest.mark.parametrize("seed", [2**64, 2**63 - 1])
def test_a_seed_beyond_63_bits_is_one_line(
    run_neurosym, tmp_path: Path, command: str, seed: int
) -> None:
    out = tmp_path / "out"
    more = () if command == "eval" else ("--out", out)
    proc = run_neurosym(command, "--checkpoint", CHECKPOINT, "--episodes", 2, "--seed", seed, *more)
    assert (proc.returncode, proc.stdout) == (1, "")
    assert proc.stderr == (
        f"neurosym {command}: error: --seed must be an integer from 0 to 9223372036854775806 "
        f"with 2 episodes (episode k plays seed SEED + k, at most 2**63 - 1), got {seed}\n"
    )
    assert not out.exists()
