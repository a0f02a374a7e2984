"""The model lab's versions: what each is, and how one model differs from the one before."""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from analysis.effects import get_effect
from analysis.model.composed import Model

if TYPE_CHECKING:       # a type only: the versions (and app.model_lab.session) import no Qt
    from app.jobs.lab_outcome import LabFit


@dataclass(frozen=True, slots=True)
class LabVersion:
    number: int          # 1, 2, ...: the x axis of the chi^2 chart
    fitted: LabFit
    how: str             # how it came about, for the chart's tooltip and the header

    @property
    def effects(self) -> str:
        return ", ".join(e.title for e in self.fitted.fit.model.effects) or "textbook"


def move_text(old: Model, new: Model) -> str:
    """What changed from `old` to `new`, by the catalogue's titles: 'added Delay of the current channel; …'."""
    before = {e.category: e for e in old.effects}
    after = {e.category: e for e in new.effects}
    moves = []
    for category, effect in before.items():
        if category not in after:
            moves.append(f"removed {effect.title}")
        elif after[category].id != effect.id:
            moves.append(f"replaced {effect.title} by {after[category].title}")
    moves += [f"added {e.title}" for c, e in after.items() if c not in before]
    return "; ".join(moves) or "refitted"


def changed_model(current: Model, checked: tuple[str, ...]) -> Model:
    """The current model with the checked effects: kept in place, swapped in place, new ones at the end."""
    chosen = {}
    for effect_id in checked:
        effect = get_effect(effect_id)
        chosen[effect.category] = effect
    effects = []
    for effect in current.effects:
        new = chosen.pop(effect.category, None)
        if new is not None:
            effects.append(new)
    return current.with_effects(effects + list(chosen.values()))
