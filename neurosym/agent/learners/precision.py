"""The arithmetic a synchronous learner runs its model in (``PPOConfig.precision``).

On a CUDA device "tf32" lets matrix products and convolutions use TF32
tensor cores, and "bf16" runs every forward under bf16 autocast (the
backward follows it; the losses, softmaxes and the optimiser stay fp32).
On the CPU every setting is fp32: TF32 does not exist there and bf16
autocast is slower than fp32 on most CPUs, and a run keeps its recorded
setting when it moves between a GPU and a CPU machine.
"""

from __future__ import annotations

import torch


class Autocast(torch.nn.Module):
    """``model`` run under bf16 autocast; its (logits, value) handed back in fp32.

    The wrapped model is ``inner`` (not ``module``, which is how the learners
    recognise DistributedDataParallel's wrapper).
    """

    def __init__(self, inner: torch.nn.Module) -> None:
        super().__init__()
        self.inner = inner

    def forward(self, obs: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        with torch.autocast(device_type="cuda", dtype=torch.bfloat16):
            logits, value = self.inner(obs)
        return logits.float(), value.float()


def effective(precision: str, device: torch.device) -> str:
    """The precision a learner on ``device`` runs: ``precision`` on CUDA, "fp32" elsewhere."""
    return precision if device.type == "cuda" else "fp32"


def apply(model: torch.nn.Module, precision: str, device: torch.device) -> torch.nn.Module:
    """Set up ``precision`` for ``model`` on ``device``; the module to call for its forwards."""
    mode = effective(precision, device)
    if mode in ("tf32", "bf16"):
        # bf16 autocast leaves fp32 products (e.g. outside autocast's list) to TF32 too
        torch.backends.cuda.matmul.allow_tf32 = True
        torch.backends.cudnn.allow_tf32 = True
    if mode == "bf16":
        return Autocast(model)
    return model
