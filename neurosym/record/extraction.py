"""The extract pipeline as a library function: an agent's episodes recorded and turned into facts.

:func:`extract` plays an agent (a checkpoint path or a loaded :class:`~neurosym.agent.agent.Agent`)
on an env, records its episodes and extracts the fact tables; it returns an
:class:`Extraction`. :func:`write_outputs` publishes the products into a folder in one step.
``neurosym extract`` and ``neurosym report --checkpoint`` are thin wrappers over the two.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from neurosym.errors import ConfigError
from neurosym.facts.tables import DEFAULT_THRESHOLD, FactSet
from neurosym.record.faithfulness import Faithfulness
from neurosym.record.recording import Recording
from neurosym.seeds import check_seed

PRODUCTS = ("kb.pl", "kb.qlf", "kb.qlf.sig", "facts", "recording")
"""what an extract run writes into --out; one run's set replaces the previous run's"""

REPORT_PAGE = "index.html"
"""the page ``neurosym report`` writes into --out: it describes the run it was built from, so
a new run removes it in the step that publishes the new products"""

_PAGE_MARK = b"<title>neurosym report: "

_FACTS = {"attends": "attends/8", "relations": "relation/7 and holds/5", "attention": "attention/6"}
"""a recording table's fact predicates, for messages"""


@dataclass(frozen=True)
class Extraction:
    """What :func:`extract` made: the env played, the recording and its fact tables."""

    checkpoint: str | None
    env: str
    env_kwargs: dict[str, Any]
    recording: Recording
    facts: FactSet
    faithfulness: Faithfulness | None = None
    """how much of the agent's choices the relation facts predict, beside controls (None: not
    measured); also in ``facts`` as faithfulness/5"""


def check_extract_options(
    episodes: int, seed: int, batch: int | None = None, top_keys: int | None = None
) -> None:
    """Refuse, in one line, counts that cannot size a recording."""
    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
        raise ConfigError(f"--episodes must be at least 1, got {episodes}")
    check_seed(seed, episodes)
    if batch is not None and batch < 1:
        raise ConfigError(f"--batch must be at least 1, got {batch}")
    if top_keys is not None and top_keys < 1:
        raise ConfigError(f"--top-keys must be at least 1, got {top_keys}")


def check_top_keys(agent: Any, top_keys: int | None) -> None:
    """Refuse, in one line, ``top_keys`` for a module without attention/6 facts."""
    from neurosym.agent.networks.adapters import adapter_class

    adapter = adapter_class(agent.config.module)
    if top_keys is not None and not adapter.has("attention"):
        facts = " and ".join(_FACTS[name] for name in adapter.tables if name in _FACTS)
        raise ConfigError(
            f"--top-keys is for MHDPA checkpoints (attention/6 facts); {agent.path} is a "
            f"{agent.config.module} (its facts are {facts})"
        )


def extract(
    agent: Any,
    env: str | None = None,
    env_kwargs: dict[str, Any] | None = None,
    *,
    episodes: int = 20,
    seed: int = 0,
    greedy: bool = True,
    threshold: str | float | Any | None = None,
    batch: int | None = None,
    top_keys: int | None = None,
    actions: str = "agent",
    progress: bool = False,
    faithfulness: bool = True,
) -> Extraction:
    """Record ``episodes`` episodes of ``agent`` on ``env`` and extract their facts.

    ``agent``: a checkpoint path (or a shipped agent's name) or a loaded Agent. ``env``: any env
    of its family with its observation shape (default: its own), ``env_kwargs`` options on top.
    ``threshold``: the relations' threshold spec (``quantile:0.9``, ``abs:X``, ``z:K``); None: the
    agent's own (:func:`model_threshold`).
    ``top_keys``: MHDPA's strongest keys kept per query cell (refused for a module without
    attention/6 facts).
    ``faithfulness``: also measure how much of the agent's choices the relation facts
    predict on held-out episodes, beside world facts and an untrained network's relation
    facts on the same states (:mod:`neurosym.record.faithfulness`; needs 2 episodes).
    """
    from neurosym.agent.agent import env_for, load_agent
    from neurosym.facts.tables import extract_facts
    from neurosym.facts.thresholds import parse_threshold
    from neurosym.record.recorder import record

    check_extract_options(episodes, seed, batch, top_keys)
    if isinstance(threshold, str):
        parse_threshold(threshold)  # a bad spec is refused before anything is played
    if isinstance(agent, str | Path):
        agent = load_agent(agent)
    check_top_keys(agent, top_keys)
    if threshold is None:
        threshold = model_threshold(agent.config)
    env, env_kwargs = env_for(agent, env, env_kwargs)
    options = dict(
        env=env, episodes=episodes, seed=seed, greedy=greedy, batch=batch,
        top_keys=top_keys or 1, env_kwargs=env_kwargs, actions=actions,
    )  # fmt: skip
    rec = record(agent, progress=progress, **options)
    facts = extract_facts(rec, threshold=threshold)
    measured = None
    if faithfulness:
        from neurosym.record.faithfulness import faithfulness as measure

        measured = measure(agent, rec, facts, **options)
        facts.tables["faithfulness"] = measured.facts()
    return Extraction(agent.path, env, env_kwargs, rec, facts, measured)


def write_outputs(
    out: Path, rec: Any, facts: Any, formats: tuple[str, ...], qlf: bool = False
) -> dict[str, Path]:
    """Write the products into ``out`` through :func:`neurosym.publish.publish`.

    Only neurosym's own names (kb.pl, kb.qlf, kb.qlf.sig, facts/, recording/)
    change in ``out``, all in one step; a killed run leaves the previous
    products as they were. Returns name -> final path.
    """
    from neurosym.publish import publish

    def write(stage: Path) -> None:
        if "pl" in formats:
            facts.to_prolog(stage / "kb.pl", qlf=qlf)
        if "parquet" in formats:
            facts.to_parquet(stage / "facts")
        rec.save(stage / "recording")

    stale = (REPORT_PAGE,) if is_report_page(out / REPORT_PAGE) else ()
    return publish(out, write, owned=PRODUCTS + stale)


def is_report_page(path: Path) -> bool:
    """Whether ``path`` is a page ``neurosym report`` wrote: its published link, or a regular
    file whose head has the page's title (another tool's index.html is left alone)."""
    import os

    from neurosym.atomic import file_kind
    from neurosym.publish import CURRENT, STORE

    if path.is_symlink():
        return os.readlink(path) == f"{STORE}/{CURRENT}/{path.name}"
    if file_kind(path) is not None or not path.is_file():
        return False
    try:
        with open(path, "rb") as page:
            return _PAGE_MARK in page.read(4096)
    except OSError:
        return False


def model_threshold(config: Any) -> str:
    """The holds/5 threshold an agent's KB is written with by default: ``abs:tau`` for the fact
    bottleneck (ModelConfig.relation_bits, so the KB's holds/5 are the bits its policy read),
    else quantile:0.9."""
    from neurosym.agent.networks.predinet import bits_threshold

    tau = bits_threshold(getattr(config, "relation_bits", None))
    return DEFAULT_THRESHOLD if tau is None else f"abs:{tau!r}"
