"""System test doubles for campaigns: frozen dataclasses (picklable, sent to Dask workers) that decide a run's
verdict from the world's world.json alone, as worldgen.campaign.systems' systems decide it from a real run."""

from __future__ import annotations

import json
import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from worldgen.files import METADATA_NAME


@dataclass(frozen=True)
class Outcome:
    verdict: str
    reason: str
    row: dict[str, Any] = field(default_factory=dict)
    seconds: float = 0.0


@dataclass(frozen=True)
class PlantedWeakness:
    """Fails only in one corner: a world at ``min_level`` or above with at least ``min_obstacles`` obstacles, at
    least ``min_people`` people and a robot at least ``min_radius`` wide; passes everywhere else.
    ``crash_people``: worlds with that many people are unjudged (the system "crashed"), never failures."""

    kind: str = "policy"
    min_level: int = 0
    min_obstacles: int = 0
    min_people: int = 1
    min_radius: float = 0.0
    crash_people: int = -1
    slow: float = 0.0  # seconds each run sleeps (a kill test needs time to kill in)

    def run(self, world: Path, task: str, run: str, workdir: Path) -> Outcome:
        meta = json.loads((Path(world) / METADATA_NAME).read_text())
        if self.slow:
            time.sleep(self.slow)
        (Path(workdir) / "pid").write_text(str(os.getpid()))
        level = meta["metrics"]["difficulty_level"]
        people = len(meta.get("people") or [])
        row = {"run": f"{meta['world_id']}__{task}__{run}", "world_id": meta["world_id"], "task": task}
        if people == self.crash_people:
            return Outcome("unjudged", "exit status 3", {}, 0.01)
        if level >= self.min_level and meta["metrics"]["obstacle_count"] >= self.min_obstacles and people >= self.min_people and meta["robot"]["radius"] >= self.min_radius:
            person = meta["people"][0]["name"] if people else "obstacle_0"
            return Outcome("failed", f"collision with {person} at {1.5 + level:.2f} s", dict(row, success=False), 0.01)
        return Outcome("passed", "", dict(row, success=True), 0.01)
