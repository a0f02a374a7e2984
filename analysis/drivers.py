"""Driver definitions: a model (effect ids) and its parameter values, as JSON files.

The virtual rig and the simulator take a driver by name (a file in
resources/drivers/) or by path. Values are SI.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from analysis.bounds import SD, Bound
from analysis.effects import parse_effects
from analysis.errors import LinparError
from analysis.files import read_text
from analysis.model.composed import Model

DRIVERS_DIR = Path(__file__).resolve().parent.parent / "resources" / "drivers"


class DriverFileError(LinparError, ValueError):
    pass


@dataclass(frozen=True)
class DriverDefinition:
    name: str
    effects: tuple[str, ...]
    parameters: dict[str, float]
    sd_m2: float | None = None
    extra: dict[str, Any] = field(default_factory=dict)

    def model(self, with_displacement: bool = True) -> Model:
        return Model(parse_effects(",".join(self.effects) or "none"), with_displacement)


def available_drivers() -> list[str]:
    return sorted(p.stem for p in DRIVERS_DIR.glob("*.json"))


def load_driver(name_or_path: str | Path = "paper") -> DriverDefinition:
    path = Path(name_or_path)
    if not path.suffix:
        path = DRIVERS_DIR / f"{name_or_path}.json"
    if not path.exists():
        raise DriverFileError(f"{path}: no such driver file; built-in drivers: {', '.join(available_drivers())}")
    text = read_text(path, "config", "a JSON driver file", DriverFileError)
    try:
        raw = json.loads(text, parse_constant=_not_a_number)
    except (json.JSONDecodeError, RecursionError, ValueError) as exc:   # ValueError: NaN, a 5000-digit integer
        raise DriverFileError(f"{path}: not a readable JSON driver file ({exc})") from None
    if not isinstance(raw, dict) or not isinstance(raw.get("parameters"), dict):
        raise DriverFileError(f"{path}: expected a JSON object with a 'parameters' object")
    effects = raw.get("effects", [])
    if not isinstance(effects, list) or not all(isinstance(e, str) for e in effects):
        raise DriverFileError(f"{path}: key 'effects': expected a list of effect ids")
    effects = tuple(effects)
    try:
        model = Model(parse_effects(",".join(effects) or "none"))
    except LinparError as exc:      # an unknown effect, two of one category
        raise DriverFileError(f"{path}: key 'effects': {exc}") from None
    params = {}
    for spec in model.param_specs:
        value = raw["parameters"].get(spec.name)
        # The model's own range of each parameter is its plausible range.
        bound = Bound(f"{spec.name}", spec.unit, spec.min, spec.max, spec.description)
        params[spec.name] = bound.check(value, f"{path}: parameters.{spec.name}", DriverFileError)
    sd = raw.get("sd_m2")
    if sd is not None:
        SD.check(sd, f"{path}: sd_m2", DriverFileError)
    return DriverDefinition(str(raw.get("name", path.stem)), effects, params,
                            float(sd) if isinstance(sd, (int, float)) else None,
                            {k: v for k, v in raw.items() if k not in ("name", "effects", "parameters", "sd_m2")})


def _not_a_number(name: str):
    raise ValueError(f"{name} is not a number")
