"""Named hook points inside the relational modules (after TransformerLens's ``HookPoint``).

Every internal value a module shows (attention maps, relation vectors, per-head
outputs) passes through a :class:`HookPoint`, an identity submodule named after
the value. Reading a value and changing it are the same mechanism, a forward
hook on its point:

* :func:`cache` keeps the values of some points during a block (introspection,
  the recorder's tables and the probes' head vectors are all read this way);
* :func:`hooked` runs functions on some points' values, and a function that
  returns a tensor replaces the value for the rest of the forward (an ablation).

A module computes a value that costs extra (MHDPA's explicit attention maps) only
when its point :attr:`HookPoint.active`: someone listens.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterable, Iterator, Mapping
from typing import Any

import torch
from torch import nn

from neurosym.errors import ConfigError

HookFn = Callable[[torch.Tensor], "torch.Tensor | None"]
"""value -> None (leave it) or the tensor that replaces it"""


class HookPoint(nn.Module):
    """Identity on one named internal value; forward hooks read or replace the value.

    Calling a point with no hooks returns its input without going through
    ``nn.Module.__call__`` (the modules run every point on every forward, training too).
    """

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return x

    def __call__(self, x: torch.Tensor) -> torch.Tensor:  # type: ignore[override]
        if self._forward_hooks:
            return super().__call__(x)
        return x

    @property
    def active(self) -> bool:
        """Whether a hook listens (values only computed for a listener are computed then)."""
        return bool(self._forward_hooks)


def hook_points(module: nn.Module) -> dict[str, HookPoint]:
    """The module's own hook points by name: its direct :class:`HookPoint` children, the
    attribute ``hook_attention`` as ``"attention"``."""
    return {
        name.removeprefix("hook_"): child
        for name, child in module.named_children()
        if isinstance(child, HookPoint)
    }


def _point(module: nn.Module, name: str) -> HookPoint:
    points = hook_points(module)
    if name not in points:
        raise ConfigError(
            f"{type(module).__name__} has no hook point {name!r}; it has {', '.join(points) or 'none'}"
        )
    return points[name]


@contextlib.contextmanager
def hooked(module: nn.Module, hooks: Iterable[tuple[str, HookFn]]) -> Iterator[None]:
    """Run ``fn(value)`` at each named point of ``module`` inside the block, in the order given.

    A function's tensor result replaces the value (later hooks at that point see the
    replacement); None leaves it. The hooks are removed when the block ends.
    """
    handles = []
    try:
        for name, fn in hooks:
            point = _point(module, name)
            handles.append(point.register_forward_hook(_wrap(fn)))
        yield
    finally:
        for handle in handles:
            handle.remove()


def _wrap(fn: HookFn) -> Callable[[nn.Module, tuple[Any, ...], torch.Tensor], Any]:
    def hook(_point: nn.Module, _args: tuple[Any, ...], value: torch.Tensor) -> Any:
        return fn(value)

    return hook


@contextlib.contextmanager
def cache(module: nn.Module, names: Iterable[str]) -> Iterator[dict[str, torch.Tensor]]:
    """Keep the named points' values inside the block: the yielded dict holds each point's
    value of the last forward (as the point passed it on, after hooks registered earlier)."""
    values: dict[str, torch.Tensor] = {}

    def keep(name: str) -> HookFn:
        def fn(value: torch.Tensor) -> None:
            values[name] = value

        return fn

    with hooked(module, [(name, keep(name)) for name in names]):
        yield values


def replace_heads(
    value: torch.Tensor, replacement: Mapping[int, torch.Tensor]
) -> torch.Tensor:
    """A copy of ``value`` (B, H, ...) with head h's slice set to ``replacement[h]``."""
    out = value.clone()
    for h in sorted(replacement):
        out[:, h] = replacement[h].to(out.dtype)
    return out


def introspected(
    module: nn.Module, record: Any, forward: Callable[[], torch.Tensor]
) -> tuple[torch.Tensor, Any]:
    """``forward()``'s output and ``record`` (a NamedTuple type) built from the cached values
    of the points named by its fields: introspection is a cache of hook values."""
    with cache(module, record._fields) as values:
        out = forward()
    return out, record(**values)
