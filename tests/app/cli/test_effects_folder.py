"""The user's effects folder among bad files (issue 31, class 5): every bad file named, the good ones loaded,
a deeply nested file one line, and the commands that build no model never read the folder."""
from pathlib import Path

import pytest

from app.cli import main

EXAMPLE = Path(__file__).resolve().parents[3] / "resources" / "effects" / "rms-sqrt-f.toml"


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def folder(tmp_path, monkeypatch):
    monkeypatch.setenv("LINPAR_EFFECTS", str(tmp_path / "effects"))
    (tmp_path / "effects").mkdir()
    (tmp_path / "effects" / "good.toml").write_text(EXAMPLE.read_text(encoding="utf-8"), encoding="utf-8")
    (tmp_path / "effects" / "a-bad.toml").write_text('id = "x"\n', encoding="utf-8")
    # 40 KB under the 64 KiB limit: tomllib recurses once per bracket.
    (tmp_path / "effects" / "b-nested.toml").write_text("a = " + "[" * 20000 + "]" * 20000 + "\n", encoding="utf-8")
    return tmp_path / "effects"


def test_every_bad_effect_file_is_named_and_the_good_ones_load(capsys, folder):
    code, out, err = run(capsys, "effects")
    assert code == 2 and err.count("\n") == 1 and err.startswith("linpar: error: 2 effect files cannot be used")
    assert str(folder / "a-bad.toml") in err and str(folder / "b-nested.toml") in err
    assert "nested too deeply" in err and "Recursion" not in err and "Traceback" not in err
    mine = out[out.index("[effects of your own]"):]
    assert "rms-sqrt-f" in mine and str(folder / "good.toml") in mine


def test_commands_that_build_no_model_do_not_read_the_effects_folder(capsys, folder, tmp_path):
    root = tmp_path / "archive"
    root.mkdir()                        # an empty archive: a folder named that does not exist is refused
    code, out, err = run(capsys, "archive", "list", "--root", root)
    assert code == 0 and "0 measurement(s)" in out, err
    code, out, err = run(capsys, "archive", "rebuild", "--root", root)
    assert code == 0, err
    code, out, err = run(capsys, "qa", "stats", "--root", root)
    assert code == 0, err
    code, out, err = run(capsys, "archive", "store", "--root", root, tmp_path / "missing")   # it fits: it reads them
    assert code == 2 and "effect files cannot be used" in err
