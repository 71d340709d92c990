"""keep_freed_memory: an update's tensors reuse freed memory instead of faulting in fresh pages."""

from __future__ import annotations

import ctypes.util
import platform
import subprocess
import sys

import pytest

from neurosym.agent.learners.allocator import keep_freed_memory

GLIBC = platform.system() == "Linux" and platform.libc_ver()[0] == "glibc"

# forward and backward over one rgw2 update batch (K = 32: 1,352 observations), in a
# fresh process, with glibc's defaults or with keep_freed_memory (argv[1]: default, keep)
CHILD = r"""
import resource, sys
import torch
from neurosym.agent.learners.allocator import keep_freed_memory
from neurosym.agent.config import ModelConfig
from neurosym.agent.networks.model import ActorCritic
from neurosym.envs import make_batched

torch.set_num_threads(1)
if sys.argv[1] == "keep":
    assert keep_freed_memory()
venv = make_batched("rgw2", 8, seed=0)
obs, _ = venv.reset(seed=0)
model = ActorCritic(ModelConfig.for_family("rgw", "predinet", tuple(obs.shape[1:])))
x = torch.as_tensor(obs).repeat(169, 1, 1, 1)  # (1352, C, H, W)
def step():
    logits, value = model(x)
    (logits.sum() + value.sum()).backward()
for _ in range(3):
    step()
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for _ in range(3):
    step()
print((resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before) // 3)
"""


def _faults_per_update(mode: str) -> int:
    proc = subprocess.run(
        [sys.executable, "-c", CHILD, mode],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    return int(proc.stdout.strip().splitlines()[-1])


@pytest.mark.skipif(not GLIBC, reason="mallopt is glibc's")
def test_takes_its_settings_on_glibc() -> None:
    assert ctypes.util.find_library("c")
    assert keep_freed_memory() is True
    assert keep_freed_memory() is True  # idempotent


@pytest.mark.skipif(not GLIBC, reason="mallopt is glibc's")
def test_update_batches_stop_faulting_in_fresh_pages() -> None:
    import resource  # Unix only, as is the test

    default, kept = _faults_per_update("default"), _faults_per_update("keep")
    # a 1,352 x 2,600 float gradient alone spans 3,433 pages of 4 KiB: with glibc's defaults
    # every update faults at least those in anew (9.9 k to 26 k faults per update, machine
    # to machine and run to run); with freed memory kept the steady-state update reuses the
    # heap (0 to a few hundred while it settles)
    one_gradient_pages = 1_352 * 2_600 * 4 // resource.getpagesize()
    assert default > one_gradient_pages, (default, one_gradient_pages)
    assert kept * 5 < default, (kept, default)


def test_learner_processes_keep_freed_memory(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every learner (A3C worker, PPO, imitation) runs inside learner_process, which sets it."""
    import queue

    from neurosym.agent.learners import process

    calls: list[bool] = []
    monkeypatch.setattr(process, "keep_freed_memory", lambda: calls.append(True) or True)
    monkeypatch.setattr(process.signal, "signal", lambda *args: None)
    monkeypatch.setattr("neurosym.agent.learners.distributed.die_with_parent", lambda: None)
    with process.learner_process(queue.Queue(), 0):
        pass
    assert calls == [True]
