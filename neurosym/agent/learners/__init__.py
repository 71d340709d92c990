"""The learners (A3C, PPO, DAgger imitation) and what they share.

Every learner is a process started the same way, ``learner(ctx)`` with a
:class:`~neurosym.agent.learners.process.LearnerContext`, and reports to the
trainer with the typed messages of :mod:`~neurosym.agent.learners.messages`.
Shared pieces: :mod:`.returns` (returns, advantages), :mod:`.optimizers`
(optimisers whose statistics live in shared memory), :mod:`.process` (what
every learner process does around its work).
"""
