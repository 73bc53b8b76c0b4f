"""A pytest helper: fail a test when its campaign found failures, naming each with the smallest world that shows it.

    from worldgen import campaign

    def test_my_planner_survives_the_campaign(tmp_path):
        campaign.run("campaign.yaml", tmp_path / "c")
        campaign.expect_no_failures(tmp_path / "c")

The test fails (``pytest.fail``, a test outcome rather than an error) with one line per distinct failure
(:func:`worldgen.campaign.report.distinct_failures`): its kind, generator, level, people and door state, how
many runs showed it, and its shrunk world's folder where the report shrank it (else the world it was first
seen in), so the message is the list of worlds to open. Unjudged runs are no failures.
"""

from __future__ import annotations

import json
from pathlib import Path

from worldgen.campaign.output import load_records
from worldgen.campaign.report import distinct_failures, slot_of
from worldgen.errors import ParameterError, require_optional
from worldgen.files import CAMPAIGN_RECIPE_NAME

__all__ = ["expect_no_failures", "failure_lines"]


def failure_lines(out) -> list[str]:
    """One line per distinct failure of campaign folder ``out`` (empty when no run failed)."""
    out = Path(out)
    if not (out / CAMPAIGN_RECIPE_NAME).is_file():
        raise ParameterError(f"'{out}' is not a campaign folder (it has no {CAMPAIGN_RECIPE_NAME})")
    lines = []
    for k, f in enumerate(distinct_failures(load_records(out))):
        kind, generator, level, people, door = f["key"]
        note = slot_of(out, k, f).with_suffix(".json")
        shrunk = json.loads(note.read_text(encoding="utf-8")) if note.is_file() else {}
        where = out / shrunk["folder"] if shrunk.get("shrunk") else out / f["record"]["folder"]
        what = "shrunk to" if shrunk.get("shrunk") else "first seen in"
        lines.append(f"{kind}: {generator}, level {level}, {people} people, doors {door}; {f['count']} run(s); "
                     f"{what} {where}")
    return lines


def expect_no_failures(out) -> None:
    """``pytest.fail`` naming every distinct failure of campaign folder ``out``; nothing when no run failed."""
    pytest = require_optional("pytest", "test", "worldgen.campaign.expect_no_failures is a pytest helper and needs pytest")
    lines = failure_lines(out)
    if lines:
        pytest.fail(f"the campaign in {out} found {len(lines)} distinct failure(s):\n" + "\n".join(f"  {x}" for x in lines),
                    pytrace=False)
