"""``neurosym report`` without a browser: the page's embedded data equal the recording's tables,
its tables are extract's figures, bad input is one line, and KB text stays inert."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import pandas as pd
import pytest
from pages import HOSTILE, HOSTILE_EVENT, SCRIPT, TAG, embedded, extract_folder, report

from neurosym.cli import main
from neurosym.facts.tables import extract_facts
from neurosym.record.heads import head_summary
from neurosym.record.recording import SCHEMA, Recording, conform
from neurosym.reports.terminal import rule_answers
from neurosym.reports.web.build import identity, stale_page
from neurosym.reports.web.player import PLAYER_TABLES, player_data


def tables_back(data: dict, name: str) -> pd.DataFrame:
    """The per-episode columns of table ``name`` put back into one recording table."""
    parts = []
    for ep in data["player"]["episodes"]:
        cols = ep["tables"][name]
        frame = pd.DataFrame(cols)
        frame.insert(0, "episode", ep["episode"])
        parts.append(frame)
    return conform(name, pd.concat(parts, ignore_index=True))


@pytest.fixture(scope="module")
def predinet_page(scripted_recording, tmp_path_factory: pytest.TempPathFactory) -> tuple[Recording, Path, str]:
    rec = scripted_recording("predinet")
    folder = extract_folder(rec, tmp_path_factory.mktemp("predinet") / "out")
    return rec, folder, report(folder)


@pytest.mark.parametrize("module", ["predinet", "mhdpa"])
def test_embedded_tables_equal_the_recording(
    scripted_recording,
    module: str, predinet_page: tuple[Recording, Path, str], tmp_path: Path
) -> None:
    if module == "predinet":
        rec, _, html = predinet_page
    else:
        rec = scripted_recording("mhdpa")
        html = report(extract_folder(rec, tmp_path / "out"))
    data = embedded(html)
    order = rec.episodes.sort_values("episode")
    assert [e["episode"] for e in data["player"]["episodes"]] == order["episode"].tolist()
    for name in PLAYER_TABLES:
        want = rec.tables[name].sort_values("episode", kind="stable").reset_index(drop=True)
        pd.testing.assert_frame_equal(tables_back(data, name), want, check_exact=True)
    for ep, row in zip(data["player"]["episodes"], order.to_dict("records"), strict=True):
        steps = rec.steps[rec.steps["episode"] == row["episode"]].sort_values("t")
        assert ep["actions"] == steps["action"].tolist()
        assert ep["rewards"] == steps["reward"].tolist()
        assert (ep["steps"], ep["return"], ep["outcome"]) == (
            row["steps"],
            row["return"],
            row["outcome"],
        )
    assert data["player"]["module"] == module
    assert data["player"]["shape"] == [10, 10]
    assert not any(name in data["player"]["episodes"][0]["tables"] for name in ("r_vectors",))


def test_terrain_is_the_map_without_its_objects(
    predinet_page: tuple[Recording, Path, str],
) -> None:
    rec, _, html = predinet_page
    data = embedded(html)
    terrain = data["player"]["terrains"][data["player"]["episodes"][0]["terrain"]]
    # Configuration-2: walls and mountains stay; the sword (0,6), the agent (0,0) and the
    # pits are objects, drawn from the positions table at each state
    assert terrain[0][6] == "empty" and terrain[0][0] == "empty"
    assert {x for row in terrain for x in row} == {"empty", "wall", "mountain"}
    start = rec.positions[(rec.positions["episode"] == 0) & (rec.positions["t"] == 0)]
    assert set(start["type"]) <= set(data["entities"])


def test_page_tables_are_extracts_figures(predinet_page: tuple[Recording, Path, str]) -> None:
    rec, folder, html = predinet_page
    for row in head_summary(rec).to_dict("records"):
        assert f'<td class="num">{row["head"]}</td><td class="num">{row["states"]}</td>' in html
    for title, goal, answers in rule_answers(folder / "kb.pl", "rgw"):
        shown = title.replace("'", "&#39;")
        assert f"<td>{shown}</td>" in html and goal in html
        for text in answers:
            assert text.replace("'", "&#39;") in html
    # episode answers link to the player
    assert '<a href="#e=0&amp;t=0">0</a>' in html
    assert html.count('<a href="#e=') >= len(rec.episodes)


def test_row_links_name_states_that_count(
    predinet_page: tuple[Recording, Path, str], tmp_path: Path
) -> None:
    rec, folder, _ = predinet_page
    out = tmp_path / "page"
    # abs:0: every relation between two objects holds, so the scripted agent has strongest rows
    args = ["--threshold", "abs:0", "--out", str(out)]
    assert main(["report", "--recording", str(folder), "--quiet", *args]) == 0
    html = (out / "index.html").read_text(encoding="utf-8")
    facts = extract_facts(rec, threshold="abs:0")
    strongest = facts.strongest_relations(5)
    assert len(strongest) == 3
    section = html[html.index('id="relations"') : html.index('id="rules"')]
    holds = facts["holds"]
    for r in strongest.to_dict("records"):
        match = holds[(holds["j"] == r["j"]) & (holds["a"] == r["a"]) & (holds["b"] == r["b"])]
        first = match.sort_values(["episode", "t"]).iloc[0]
        assert f'href="#e={first.episode}&amp;t={first.t}"' in section
    # head 1's top pair agent-teleport: its first state is the first where a1, a2 are on them
    att = rec.attends[rec.attends["head"] == 1]
    a1 = att[(att["arg"] == 1) & (att["entity"] == "agent")][["episode", "t"]]
    a2 = att[(att["arg"] == 2) & (att["entity"] == "teleport")][["episode", "t"]]
    e, t = a1.merge(a2).sort_values(["episode", "t"]).iloc[0]
    heads = html[html.index('id="heads"') : html.index('id="relations"')]
    assert f'agent-teleport</span> 1 %: <a href="#e={e}&amp;t={t}">' in heads


def test_report_from_a_checkpoint_writes_extracts_products(run_neurosym, tmp_path: Path) -> None:  # noqa: ANN001
    out = tmp_path / "page"
    done = run_neurosym(
        "report", "--checkpoint", "checkpoints/rgw2-predinet.pt", "--episodes", "2",
        "--seed", "0", "--out", out,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == f"wrote {out / 'index.html'}"
    assert sorted(p.name for p in out.iterdir()) == [
        ".neurosym",
        "index.html",
        "kb.pl",
        "recording",
    ]
    html = (out / "index.html").read_text(encoding="utf-8")
    rec = Recording.load(out / "recording")
    assert tables_back(embedded(html), "attends").equals(rec.attends)
    assert "rgw2-predinet.pt on rgw2" in html
    assert "<dt>learner</dt><dd>a3c</dd>" in html
    assert "<dt>frames, whole training</dt><dd>505,601</dd>" in html
    assert "the checkpoint&#39;s card (held-out evaluation)" in html
    # the card's figures by readable names, shares in percent
    assert "<dt>held-out, sampled: sword first when guarded</dt><dd>6.7 %</dd>" in html
    assert "held_out." not in html and "sword_first_guarded" not in html
    assert (
        f'<meta name="neurosym-recording" content="{identity(out / "recording", out / "kb.pl")}">'
        in html
    )


def test_boxworld_page(explorer_recording, tmp_path: Path) -> None:
    rec = explorer_recording("bw2", episodes=3)
    html = report(extract_folder(rec, tmp_path / "out"))
    data = embedded(html)
    assert data["player"]["shape"] == [14, 14]
    assert tables_back(data, "events").equals(
        rec.events.sort_values("episode", kind="stable").reset_index(drop=True)
    )
    assert "followed the solution chain" in html and "key opens lock" in html
    assert any(name.startswith("key(") for name in data["entities"])


def test_probe_and_intervene_sections(
    predinet_page: tuple[Recording, Path, str], tmp_path: Path
) -> None:
    _, folder, _ = predinet_page
    probe, intervene = tmp_path / "probe", tmp_path / "intervene"
    probe.mkdir()
    intervene.mkdir()
    pd.DataFrame(
        {
            "head": [0, 0, 1],
            "relation": ["0", "all", "3"],
            "predicate": ["holding(sword)", "left_of(agent,enemy)", "above(agent,pit_1)"],
            "accuracy": [0.9, 0.95, 0.8],
            "control": [0.6, 0.55, 0.7],
            "selectivity": [0.3, 0.4, 0.1],
        }
    ).to_parquet(probe / "probes.parquet")
    rows = {"experiment": ["baseline", "remove_sword"], "measure": ["return", "return"]}
    pd.DataFrame({**rows, "value": [10.68, -0.4]}).to_parquet(intervene / "measures.parquet")
    pd.DataFrame({**rows, "value": [0.0, -11.08]}).to_parquet(intervene / "effects.parquet")
    out = tmp_path / "page"
    args = ["--probe", str(probe), "--intervene", str(intervene), "--out", str(out)]
    assert main(["report", "--recording", str(folder), "--quiet", *args]) == 0
    html = (out / "index.html").read_text(encoding="utf-8")
    probes = html[html.index('id="probes"') : html.index('id="experiments"')]
    # head 0's probes, most selective first
    assert probes.index("left_of(agent,enemy)") < probes.index("holding(sword)")
    assert "+0.400" in probes and "above(agent,pit_1)" in probes
    assert '<td class="num">-0.400 (-11.080)</td>' in html
    assert not (folder / "index.html").read_text() == html  # --out: the folder's page untouched


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--recording", "{tmp}"], "holds no recording: give the folder `neurosym extract --out`"),
        (["--recording", "{folder}", "--episodes", "3"], "--episodes go(es) with --checkpoint"),
        (["--recording", "{folder}", "--probe", "{tmp}"], "has no probes.parquet"),
        (["--recording", "{folder}", "--intervene", "{tmp}"], "has no measures.parquet"),
        (["--checkpoint", "x.pt", "--episodes", "0"], "--episodes must be at least 1, got 0"),
        (["--recording", "{folder}", "--threshold", "most"], "threshold"),
    ],
)
def test_bad_input_is_one_line(
    args: list[str],
    message: str,
    predinet_page: tuple[Recording, Path, str],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    _, folder, _ = predinet_page
    argv = [a.format(tmp=tmp_path, folder=folder) for a in args]
    assert main(["report", *argv]) == 1
    err = capsys.readouterr().err
    assert err.startswith("neurosym report: error: ") and message in err
    assert err.count("\n") == 1


def test_hostile_text_stays_text(hostile_recording, tmp_path: Path) -> None:
    rec = hostile_recording()
    html = report(extract_folder(rec, tmp_path / "out"))
    assert SCRIPT not in html and TAG not in html
    assert html.lower().count("<script") == 2  # the data block and the page's own script
    data = embedded(html)
    assert HOSTILE in data["entities"]
    assert HOSTILE_EVENT in {
        e for ep in data["player"]["episodes"] for e in ep["tables"]["events"]["event"]
    }
    csp = re.search(r"script-src '(sha256-[A-Za-z0-9+/=]+)'", html)
    assert csp is not None  # only the page's own script, by hash, may run


def test_recording_subfolder_and_a_missing_checkpoint(
    predinet_page: tuple[Recording, Path, str], tmp_path: Path
) -> None:
    _, folder, html = predinet_page
    out = tmp_path / "page"
    args = ["--recording", str(folder / "recording"), "--out", str(out), "--quiet"]
    assert main(["report", *args]) == 0
    again = (out / "index.html").read_text(encoding="utf-8")
    assert embedded(again) == embedded(html)
    assert "sword before enemy" in again  # kb.pl found beside recording/
    # the recording names scripted.pt, which is not a file: the card says so
    assert "The checkpoint scripted.pt the recording names is not at hand" in again
    assert "none: the checkpoint is not at hand" in again


def test_card_prefers_the_checkpoints_own_card() -> None:
    from types import SimpleNamespace

    from neurosym.reports.web.card import agent_card

    meta = {"frames": 1200, "metrics": {"greedy_return": 10.7}, "train_config": {"algo": "ppo"}}
    agent = SimpleNamespace(env_name="rgw-random", env_kwargs={}, meta=meta)
    rec_meta = {"env": "rgw2", "module": "mhdpa", "heads": 2, "seed": 0, "checkpoint": "a.pt"}
    plain = agent_card(rec_meta, agent)
    assert plain["figures"] == [("greedy_return", "10.7")]
    assert plain["figures_from"].startswith("the last figures of training (not held out")
    assert ("learner", "ppo") in plain["rows"] and ("frames, whole training", "1,200") in plain[
        "rows"
    ]
    held = {"role": "a test agent", "eval_command": "neurosym eval ... --json",
            "held_out": {"env": "rgw-random", "env_options": {"num_mountains": 6}, "episodes": 300,
                         "seed": 3000000000,
                         "sampled": {"success_rate": 0.987, "sword_first_guarded": 1.0},
                         "greedy": {"success_rate": 0.9512}}}  # fmt: skip
    card = agent_card(
        rec_meta, SimpleNamespace(**{**vars(agent), "meta": {**meta, "meta": {"card": held}}})
    )
    assert card["figures"] == [
        ("role", "a test agent"),
        (
            "held-out levels",
            "300 levels of rgw-random (num_mountains=6), reset seeds from 3000000000",
        ),
        ("held-out, sampled: success", "98.7 %"),
        ("held-out, sampled: sword first when guarded", "100.0 %"),
        ("held-out, greedy: success", "95.1 %"),
        ("measured by", "neurosym eval ... --json"),
    ]
    assert card["figures_from"] == "the checkpoint's card (held-out evaluation)"
    top = agent_card(rec_meta, SimpleNamespace(**{**vars(agent), "meta": {**meta, "card": held}}))
    assert top["figures"] == card["figures"]  # a card at the payload's top level reads the same
    # a malformed card: the training figures, and a note naming the field
    bad = {**held, "held_out": {"greedy": {"success_rate": 0.5}}}
    broken = agent_card(rec_meta, SimpleNamespace(**{**vars(agent), "meta": {**meta, "card": bad}}))
    assert broken["figures"] == [("greedy_return", "10.7")]
    assert broken["figures_from"].endswith("(not held out: its card is malformed)")
    assert broken["note"] == (
        "Its card is not shown: the card: held_out lacks its 'sampled' figures "
        "(held_out.sampled must be a dict)."
    )


def test_frames_are_the_whole_trainings_where_the_checkpoint_records_them() -> None:
    """A curriculum step counts from 0 and records its source's frames; a resume adds to frames."""
    from neurosym.cards import training_frames

    one = "neurosym train --env bw1 --out a && neurosym train --env bw2 --init-from a.pt --out b"
    init = {"init_from": "a.pt", "init_frames": 4_500_955}
    assert training_frames({"frames": 7_052_189, "command": one, "metrics": init}) == (
        "frames, whole training",
        "11,553,144 (7,052,189 in its last run, after 4,500,955 of a.pt)",
    )
    two = f"{one} && neurosym train --env bw3 --init-from b.pt --out c"
    assert training_frames({"frames": 10, "command": two, "metrics": init})[1].startswith(
        "at least 4,500,965 ("
    )
    assert training_frames({"frames": 10, "command": one, "metrics": {}}) == (
        "frames in the last run",
        "10 (it started from another agent's weights)",
    )
    resumed = "neurosym train --env rgw2 --out r && neurosym train --out r --resume"
    assert training_frames({"frames": 505_601, "command": resumed, "metrics": {}}) == (
        "frames, whole training",
        "505,601",
    )


def received(folder: Path, out: Path, **meta: object) -> Path:
    """A copy of the extract ``folder`` (kb.pl, recording/) with ``meta`` in its meta.json."""
    out.mkdir()
    shutil.copy(folder / "kb.pl", out / "kb.pl")
    shutil.copytree(folder / "recording", out / "recording")
    path = out / "recording" / "meta.json"
    head = json.loads(path.read_text())
    head["meta"].update(meta)
    path.write_text(json.dumps(head))
    return out


@pytest.mark.parametrize(
    ("checkpoint", "why"),
    [
        ("bw2-predinet", "it was trained on bw2, a boxworld env; the recording is of rgw2"),
        ("rgw2-mhdpa", "its module is mhdpa, the recording&#39;s predinet"),
    ],
)
def test_a_recording_naming_another_agent_shows_no_card(
    checkpoint: str, why: str, predinet_page: tuple[Recording, Path, str], tmp_path: Path
) -> None:
    _, folder, _ = predinet_page
    path = Path(__file__).resolve().parents[2] / "checkpoints" / f"{checkpoint}.pt"
    copy = received(folder, tmp_path / "got", checkpoint=str(path))
    html = report(copy)
    assert f"The checkpoint {path} the recording names is not the agent recorded ({why}" in html
    assert "its card is not shown" in html and "held-out" not in html
    assert "none: the checkpoint is not at hand" in html


@pytest.mark.parametrize(
    ("meta", "message"),
    [
        ({"heads": "four"}, "/recording/meta.json gives heads 'four'; expected a whole number from 0 to 1024"),
        ({"heads": 2.5}, "/recording/meta.json gives heads 2.5; expected a whole number from 0 to 1024"),
        ({"heads": 10**6}, "/recording/meta.json gives heads 1000000; expected a whole number from 0 to 1024"),
        ({"seed": -1}, ": its recording's meta.json has seed -1; it must be a whole number, 0 or more"),
        ({"env": ["rgw2"]}, ": its recording's meta.json has env ['rgw2']; it must be text"),
        ({"note": [[[[[[[[[[[[[[[[[[[[[0]]]]]]]]]]]]]]]]]]]]]},
         ": its recording's meta.json is nested more than 20 levels deep"),
    ],
)  # fmt: skip
def test_a_bad_recording_meta_is_one_line(
    meta: dict,
    message: str,
    predinet_page: tuple[Recording, Path, str],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    _, folder, _ = predinet_page
    copy = received(folder, tmp_path / "got", **meta)
    assert main(["report", "--recording", str(copy), "--quiet"]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"neurosym report: error: {copy}{message}")
    assert err.count("\n") == 1 and not (copy / "index.html").exists()


@pytest.fixture(scope="session")
def non_finite_recording(scripted_recording):  # noqa: ANN201
    """``non_finite_recording(...)``, built from the shared builders."""
    def non_finite_recording() -> Recording:
        """The scripted recording with reward +inf at its first step and relation values -inf, NaN."""
        rec = scripted_recording("predinet")
        steps, relations = rec.steps.copy(), rec.relations.copy()
        steps.loc[steps.index[0], "reward"] = float("inf")
        relations.loc[relations.index[0], "value"] = float("-inf")
        relations.loc[relations.index[1], "value"] = float("nan")
        tables = {name: rec.tables[name] for name in SCHEMA}
        return Recording(**{**tables, "steps": steps, "relations": relations}, meta=rec.meta)
    return non_finite_recording


def test_non_finite_values_reach_the_page_as_null(non_finite_recording) -> None:
    """JSON has no NaN or infinity: the page's data say null where a recording has one (a
    recording read from disk never has one: Recording.load refuses it, see the next test)."""
    bad = non_finite_recording()
    data = json.loads(json.dumps(player_data(bad), allow_nan=False))
    first = bad.steps.iloc[0]
    assert data["episodes"][int(first["episode"])]["rewards"][int(first["t"])] is None
    values = [v for ep in data["episodes"] for v in ep["tables"]["relations"]["value"]]
    assert values.count(None) == 2 and all(v is None or abs(v) < 1e300 for v in values)


def test_a_recording_with_a_non_finite_value_is_one_line(
    predinet_page: tuple[Recording, Path, str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _, folder, _ = predinet_page
    copy = received(folder, tmp_path / "got")
    steps = pd.read_parquet(copy / "recording" / "steps.parquet")
    steps.loc[steps.index[0], "reward"] = float("inf")
    steps.to_parquet(copy / "recording" / "steps.parquet")
    assert main(["report", "--recording", str(copy), "--quiet"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("neurosym report: error: ") and err.count("\n") == 1
    assert "recording table 'steps' has inf in column 'reward' (row 0)" in err
    assert not (copy / "index.html").exists()


def test_a_probe_table_with_a_non_integer_head_is_one_line(
    predinet_page: tuple[Recording, Path, str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _, folder, _ = predinet_page
    for name, heads in (
        ("words", ["a", "0"]),
        ("halves", [0.5, 1.0]),
        ("nan", [0.0, float("nan")]),
    ):
        probe = tmp_path / name
        probe.mkdir()
        pd.DataFrame({"head": heads, "relation": ["0", "all"], "predicate": ["p", "q"],
                      "accuracy": [0.9, 0.8], "control": [0.6, 0.7],
                      "selectivity": [0.3, 0.1]}).to_parquet(probe / "probes.parquet")  # fmt: skip
        out = ["--out", str(tmp_path / "page")]
        assert main(["report", "--recording", str(folder), "--probe", str(probe), *out]) == 1
        err = capsys.readouterr().err
        bad = heads[0] if name != "nan" else "nan"
        want = f"neurosym report: error: {probe / 'probes.parquet'}: head {bad!r} is not a whole number"
        assert err.startswith(want.replace("'nan'", "nan")) and err.count("\n") == 1


def test_the_page_is_its_kbs_and_a_stale_one_is_told_and_rebuilt(
    scripted_recording,
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A page carries the identity of the recording and KB it was built from; re-extracting
    beside it makes it stale, report says so, and report --recording publishes a new one."""
    rec = scripted_recording("predinet")
    folder = extract_folder(rec, tmp_path / "out")
    html = report(folder)
    first = identity(folder / "recording", folder / "kb.pl")
    assert f'<meta name="neurosym-recording" content="{first}">' in html
    assert (folder / "index.html").is_symlink()  # published with the KB, as one product
    assert stale_page(folder, first) is None
    again = Recording(**{n: rec.tables[n] for n in SCHEMA}, meta={**rec.meta, "seed": 777})
    extract_folder(again, folder)  # extract again, and the old page beside the new KB:
    (folder / "index.html").unlink(missing_ok=True)  # as extract leaves it, or a copy brings it
    (folder / "index.html").write_text(html, encoding="utf-8")
    now = identity(folder / "recording", folder / "kb.pl")
    assert now != first
    assert stale_page(folder, now) == (
        f"{folder / 'index.html'} was built from another recording or KB than the one beside it"
    )
    assert main(["report", "--recording", str(folder), "--out", str(tmp_path / "else")]) == 0
    assert capsys.readouterr().err == (
        f"note: {folder / 'index.html'} was built from another recording or KB than the one "
        f"beside it; `neurosym report --recording {folder}` rebuilds it\n"
    )
    html = report(folder)
    assert stale_page(folder, now) is None and "seed 777)" in html and "seed 0)" not in html


def test_a_page_is_not_published_beside_a_kb_extracted_while_it_was_built(
    scripted_recording,
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import neurosym.reports.web.page as page_module

    rec = scripted_recording("predinet")
    folder = extract_folder(rec, tmp_path / "out")
    again = Recording(**{n: rec.tables[n] for n in SCHEMA}, meta={**rec.meta, "seed": 777})
    render = page_module.render

    def extract_meanwhile(context: dict) -> str:
        extract_folder(again, folder)
        return render(context)

    monkeypatch.setattr(page_module, "render", extract_meanwhile)
    assert main(["report", "--recording", str(folder), "--quiet"]) == 1
    assert capsys.readouterr().err == (
        f"neurosym report: error: {folder} was extracted again while its report was built; "
        f"nothing was written: run `neurosym report --recording {folder}` again\n"
    )
    assert not (folder / "index.html").exists()
    assert "kb_meta(seed,777)" in (folder / "kb.pl").read_text()  # the new KB, untouched
