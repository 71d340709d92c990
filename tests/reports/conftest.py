"""Fixtures of the report-page tests."""

from __future__ import annotations

import pytest
from pages import HOSTILE, HOSTILE_EVENT

from neurosym.record.recording import SCHEMA, Recording


@pytest.fixture(scope="session")
def hostile_recording(scripted_recording):  # noqa: ANN201
    """``hostile_recording()``: the scripted recording with an object type and an event only a
    hostile KB would have."""

    def hostile_recording() -> Recording:
        rec = scripted_recording("predinet")
        positions = rec.positions.copy()
        positions.loc[positions["type"] == "sword", "type"] = HOSTILE
        events = rec.events.copy()
        events.loc[events.index[0], "event"] = HOSTILE_EVENT
        tables = {name: rec.tables[name] for name in SCHEMA}
        return Recording(**{**tables, "positions": positions, "events": events}, meta=rec.meta)
    return hostile_recording
