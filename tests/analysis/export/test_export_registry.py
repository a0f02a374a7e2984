"""The export registry: the formats are found in analysis.export's modules, so a
new format is one module that defines EXPORTERS (and its test); the CLI's
options and the GUI's file types come from the registry."""
import json
import sys
import textwrap

import pytest

from analysis.archive.results import StoredResult, results_document
from analysis.export import export_bytes, exporters, registry, write_exports
from analysis.pipeline import analyze_recording
from tests.builders import recording


def test_the_formats_in_their_listing_order():
    assert list(exporters()) == ["csv", "json", "zma", "zma_model", "frd", "frd_model", "driver"]
    assert [e.kind for e in exporters().values() if not e.needs_fit] == ["csv", "json"]


def test_a_new_format_is_one_module(tmp_path, monkeypatch):
    """A toy format dropped into the package is exported, offered by `linpar export` and the GUI, with no other
    file touched."""
    import analysis.export as package
    module = tmp_path / "toy_format.py"
    module.write_text(textwrap.dedent('''
        from analysis.export.registry import Exporter

        def toy(result, header):
            return f"{len(result.parameters)} parameters of {header.get('driver', '?')}\\n".encode()

        EXPORTERS = (Exporter("toy", "Toy summary", ".toy", toy, needs_fit=False),)
    '''), encoding="utf-8")
    monkeypatch.setattr(package, "__path__", [*package.__path__, str(tmp_path)])
    monkeypatch.setattr(registry, "_found", {})
    monkeypatch.delitem(sys.modules, "analysis.export.toy_format", raising=False)
    rec = recording(n_periods=2, seed=3)
    stored = StoredResult.from_json(json.loads(json.dumps(results_document(analyze_recording(rec), rec))))
    assert list(exporters())[-1] == "toy"
    [path] = write_exports(stored, {"toy": tmp_path / "r.toy"}, {"driver": "W6"})
    assert path.read_text() == f"{len(stored.parameters)} parameters of W6\n"

    from app.cli.report import export_options
    from app.window.menus import data_filters, suffix_kind
    assert ("toy", "Toy summary (.toy)") in export_options()
    assert data_filters()["Toy summary (*.toy)"] == "toy" and suffix_kind()[".toy"] == "toy"


def test_an_unknown_kind_lists_the_known_ones():
    with pytest.raises(ValueError, match="unknown export 'xlsx'; known: csv, json, zma"):
        export_bytes("xlsx", None)
