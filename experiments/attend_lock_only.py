"""Box-World's attention target without the held key: does head 0 pair the key with its lock unasked?

    python experiments/attend_lock_only.py train --env bw2 --init-from INIT --algo imitate \
        --set teacher=checkpoints/bw2-predinet.pt --set attend_coef=1 ... --out RUN

Runs ``neurosym`` with :class:`neurosym.envs.boxworld_solver.RouteTargets` changed so that
only head 0's second argument is taught (the next key or lock on the route), never its first
(the held key at a lock it opens): the control for the shipped Box-World bottlenecks, whose
key-lock pair is taught whole. The learner is forked (CPU), so it runs the changed targets;
the run's checkpoint records the command as given (``attend_coef=1``), not this change.
"""

from __future__ import annotations

import sys

from neurosym.cli import main
from neurosym.envs.boxworld_solver import RouteTargets

taught = RouteTargets._first_contact


def second_only(*args: object) -> tuple[int, int]:
    """The route's next object for the second argument; nothing for the first."""
    _, cell = taught(*args)
    return (-1, cell)


if __name__ == "__main__":
    RouteTargets._first_contact = staticmethod(second_only)
    sys.exit(main(sys.argv[1:]))
