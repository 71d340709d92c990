"""The agent network: encoder -> relational module (PrediNet or MHDPA) -> actor-critic MLP."""
