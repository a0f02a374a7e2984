"""What sending a station's local queue to the archive's server did (every back end's `sync` returns one)."""
from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class SyncReport:
    """What sending the local queue to the server did."""

    sent: list[str] = field(default_factory=list)          # ids now on the server
    already: list[str] = field(default_factory=list)       # ids the server had already (sent before a break)
    waiting: int = 0                                       # still in the local queue
    problem: str = ""                                      # why they wait ("" when none do)
    refused: bool = False                                  # the server said no (not: could not be reached)
    stuck: list[str] = field(default_factory=list)         # "id: why" of those the server refuses one by one

    def describe(self) -> str:
        text = f"{len(self.sent)} sent" + (f", {len(self.already)} already on the server" if self.already else "")
        if self.waiting:
            why = "; ".join(x for x in (self.problem, *self.stuck[:3]) if x)
            text += f"; {self.waiting} wait in the local queue ({why})"
        return text
