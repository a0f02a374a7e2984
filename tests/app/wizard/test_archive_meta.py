"""The archive's metadata of a wizard's measurement (app.wizard.archive_meta): every field from the request."""
from __future__ import annotations

from types import SimpleNamespace

from app.wizard.archive_meta import measurement_meta


def test_the_metadata_carries_the_driver_the_settings_and_the_calibration():
    request = SimpleNamespace(
        driver=SimpleNamespace(name="W18", serial="S-001", operator="Ann", station="bench 2"),
        template=SimpleNamespace(as_json=lambda: {"name": "woofer"}), level_v=0.5, level_reason="the level step",
        hardware=SimpleNamespace(describe=lambda: "the in-process simulator"),
        corrections=SimpleNamespace(to_dict=lambda: {"current": 1.01}))
    assert measurement_meta(request) == {
        "driver": "W18", "serial": "S-001", "operator": "Ann", "station": "bench 2",
        "settings": {"template": {"name": "woofer"}, "level_v_rms": 0.5, "level_reason": "the level step",
                     "hardware": "the in-process simulator"},
        "calibration": {"corrections": {"current": 1.01}}}
