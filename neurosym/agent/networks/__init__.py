"""The agent network: encoder -> relational module (PrediNet, MHDPA or any module registered
in :mod:`~neurosym.agent.networks.adapters`) -> actor-critic MLP; the modules' internal values
are named hook points (:mod:`~neurosym.agent.networks.hooks`)."""
