"""Driver definitions: a model (effect ids) and its parameter values, as JSON files.

The virtual rig and the simulator take a driver by name (a file in
resources/drivers/) or by path. Values are SI.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from analysis.effects import parse_effects
from analysis.errors import LinparError
from analysis.model import Model

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
    try:
        raw = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise DriverFileError(f"{path}: no such driver file; built-in drivers: {', '.join(available_drivers())}") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise DriverFileError(f"{path}: not a readable JSON driver file ({exc})") from None
    if not isinstance(raw, dict) or not isinstance(raw.get("parameters"), dict):
        raise DriverFileError(f"{path}: expected a JSON object with a 'parameters' object")
    effects = tuple(raw.get("effects", []))
    try:
        model = Model(parse_effects(",".join(effects) or "none"))
    except (KeyError, ValueError) as exc:
        raise DriverFileError(f"{path}: key 'effects': {exc}") from None
    params = {}
    for spec in model.param_specs:
        value = raw["parameters"].get(spec.name)
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            raise DriverFileError(f"{path}: parameters.{spec.name}: expected a number in {spec.unit}")
        params[spec.name] = float(value)
    sd = raw.get("sd_m2")
    return DriverDefinition(str(raw.get("name", path.stem)), effects, params,
                            float(sd) if isinstance(sd, (int, float)) else None,
                            {k: v for k, v in raw.items() if k not in ("name", "effects", "parameters", "sd_m2")})
