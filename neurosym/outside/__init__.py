"""Agents trained outside neurosym: a user's PyTorch module, or a Stable-Baselines3 model.

Every command that takes ``--checkpoint`` takes them too (:mod:`neurosym.outside.load`):

    neurosym extract --checkpoint my_agent.py:make_agent --episodes 20
    neurosym extract --checkpoint ppo_rgw2.zip --env rgw2

where ``my_agent.py`` says how its network acts and which layer holds attention::

    from neurosym.outside import TorchAgent

    def make_agent():
        net = MyNet()
        net.load_state_dict(torch.load("my_net.pt", weights_only=True))
        return TorchAgent(net, env="rgw2", attention="attn")   # net(obs) -> logits

Its attention weights become attention/6 facts, its heads can be ablated (``intervene``),
and its behaviour is recorded like any agent's.
"""

from neurosym.outside.agent import OutsideAgent, OutsideConfig, TorchAgent
from neurosym.outside.load import load_outside, outside_spec
from neurosym.outside.sb3 import sb3_agent

__all__ = [
    "OutsideAgent",
    "OutsideConfig",
    "TorchAgent",
    "load_outside",
    "outside_spec",
    "sb3_agent",
]
