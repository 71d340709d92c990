"""The training run: configuration, the ``neurosym train`` command and the trainer."""
