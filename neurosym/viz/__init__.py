"""Pictures of what the agent relates: attention maps, R vectors, relation values, episodes.

Each function takes a :class:`~neurosym.record.recording.Recording`, an
:class:`~neurosym.agent.agent.Agent` (played greedily on ``env`` from
``reset(seed)``) or an :class:`EpisodeTrace`, and returns a matplotlib Figure
(headless, no pyplot); :func:`save_figure` writes PNG or SVG reproducibly.

    >>> from neurosym.viz import predinet_figure, save_figure
    >>> fig = predinet_figure(load_agent("checkpoints/rgw2-predinet.pt"), "rgw2", step=3)
    >>> save_figure(fig, "heads.png")

Names are imported lazily so that ``neurosym plot --help`` does not load matplotlib.
"""

from __future__ import annotations

from neurosym.lazy import lazy_attributes

_LAZY = {
    "mhdpa_figure": "neurosym.viz.attention",
    "predinet_figure": "neurosym.viz.predinet",
    "r_vectors_figure": "neurosym.viz.predinet",
    "relations_figure": "neurosym.viz.relations",
    "relation_values": "neurosym.viz.relations",
    "episode_figure": "neurosym.viz.episode",
    "episode_frames": "neurosym.viz.episode",
    "save_episode_gif": "neurosym.viz.episode",
    "save_figure": "neurosym.viz.output",
    "save_gif": "neurosym.viz.output",
    "EpisodeTrace": "neurosym.viz.trace",
    "load_trace": "neurosym.viz.sources",
    "trace_from_recording": "neurosym.viz.recorded",
    "trace_from_agent": "neurosym.viz.live",
}

__all__ = list(_LAZY)


__getattr__ = lazy_attributes(__name__, _LAZY)
