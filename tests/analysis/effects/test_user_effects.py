"""Effects of the user's own: the formula language, the file format, the registry, and the fit with them."""
import math
import pickle
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from analysis.effects import UnknownEffectError, get_effect, parse_effects, registry
from analysis.effects.base import Site
from analysis.effects.file_error import EffectFileError
from analysis.effects.formula import FUNCTIONS, FormulaError, parse_formula
from analysis.effects.user import UserEffect, effect_from_text, load_effect_file
from analysis.fit.least_squares import FitData, fit_model
from analysis.model.composed import Model, ModelError
from analysis.spectra import estimate_spectra
from tests.builders import PAPER, REPO_ROOT, TYPICAL_NOISE, recording

EXAMPLE = REPO_ROOT / "resources" / "effects" / "rms-sqrt-f.toml"
W = 2 * np.pi * np.array([5.0, 70.0, 1000.0, 10e3])
WS = 2 * np.pi * 70.0


def effect_text(formula="r * w", site="electrical", parameters='[parameters.r]\nunit = "1"\nstart = 0.5\nmin = -1\nmax = 1',
                extra="", effect_id="mine"):
    return (f'id = "{effect_id}"\ntitle = "A test effect"\nsite = "{site}"\nformula = "{formula}"\n'
            f'physics = "Whatever the test needs."\n{extra}\n{parameters}\n')


# -- the formula language -----------------------------------------------------------------------

@pytest.mark.parametrize("text, expected", [
    ("r * (sqrt(w / ws) - 1)", lambda r: r * (np.sqrt(W / WS) - 1)),
    ("s", lambda r: 1j * W),
    ("f", lambda r: W / (2 * np.pi)),
    ("2 * pi * f - w", lambda r: 0 * W),
    ("-r ** 2", lambda r: -(r**2) + 0 * W),          # ** binds tighter than unary minus, as in Python
    ("r * j * w / (1 + s / ws)", lambda r: r * 1j * W / (1 + 1j * W / WS)),
    ("exp(-s * r * 1e-3)", lambda r: np.exp(-1j * W * r * 1e-3)),
    ("log10(w / ws) + log(w) - tanh(w / ws)", lambda r: np.log10(W / WS) + np.log(W) - np.tanh(W / WS)),
    ("abs(s) + real(s) + imag(s) + arctan(w / ws)", lambda r: W + 0 + W + np.arctan(W / WS)),
    ("sin(w) * cos(w) / tan(w + 1)", lambda r: np.sin(W) * np.cos(W) / np.tan(W + 1)),
    ("(s / ws) ** -r", lambda r: (1j * W / WS) ** -r),
    ("2j * w", lambda r: 2j * W),
])
def test_a_formula_evaluates_as_written(text, expected):
    r = 0.7
    value = parse_formula(text, ("r",)).evaluate(1j * W, WS, {"r": r})
    np.testing.assert_allclose(value, expected(r), rtol=1e-12, atol=1e-12)


def test_every_function_of_the_language_is_allowed_and_nothing_else_is_called():
    for name in FUNCTIONS:
        assert np.all(np.isfinite(parse_formula(f"{name}(w / ws + 0.1)").evaluate(1j * W, WS, {})))
    assert set(FUNCTIONS) == {"sqrt", "exp", "log", "log10", "abs", "sin", "cos", "tan", "tanh", "arctan", "real",
                              "imag"}


@pytest.mark.parametrize("text, column, words", [
    ("r * q", 5, "unknown name 'q'"),
    ("__import__('os').system('true')", 1, "is not one of the functions"),
    ("open('/etc/passwd')", 1, "is not one of the functions"),
    ("r.__class__", 1, "is not allowed"),
    ("r[0]", 1, "is not allowed"),
    ("(lambda: 1)()", 1, "is not one of the functions"),
    ("r if r else 1", 1, "is not allowed"),
    ("r < 1", 1, "is not allowed"),
    ("r ^ 2", 1, "write **"),
    ("sqrt(w, 2)", 1, "exactly one argument"),
    ("sqrt(x=w)", 1, "exactly one argument"),
    ("sqrt", 1, "needs an argument"),
    ("'text'", 1, "is not a number"),
    ("True * w", 1, "is not a number"),
    ("[w]", 1, "is not allowed"),
    ("  r * k", 7, "unknown name 'k'"),
])
def test_anything_outside_the_language_is_refused_with_its_column(text, column, words):
    with pytest.raises(FormulaError) as info:
        parse_formula(text, ("r",))
    assert info.value.column == column
    assert words in str(info.value)


@pytest.mark.parametrize("text", ["", "   ", "r +", "r\n+ 1", "r; 1", "r" + " + r" * 200, "(" * 240 + "r" + ")" * 240])
def test_empty_broken_multi_line_or_too_long_formulas_are_refused(text):
    with pytest.raises(FormulaError):
        parse_formula(text, ("r",))


def test_the_formula_is_never_executed_by_python(monkeypatch):
    # Were the text handed to eval, this would call the patched function.
    import builtins
    called = []
    monkeypatch.setattr(builtins, "print", lambda *a, **k: called.append(a))
    with pytest.raises(FormulaError):
        parse_formula("print(1)")
    assert not called


def test_huge_powers_overflow_to_infinity_instead_of_hanging():
    value = parse_formula("9 ** 9 ** 9 * w").evaluate(1j * W, WS, {})
    assert not np.isfinite(value).any()


# -- the file format ----------------------------------------------------------------------------

def test_the_example_file_loads_as_the_issue_writes_it():
    effect = load_effect_file(EXAMPLE)
    assert effect.id == "rms-sqrt-f" and effect.site is Site.MECHANICAL and effect.param_names == ("r",)
    spec = effect.params[0]
    assert (spec.unit, spec.default, spec.min, spec.max) == ("kg/s", 0.5, -10.0, 10.0)
    assert effect.category == "rms-sqrt-f"          # a category of its own when the file names none
    assert "r * (sqrt(w / ws) - 1)" in effect.describe()["formula"]
    assert effect.needs_bl and effect.needs_displacement


def test_optional_keys_are_kept():
    text = effect_text(extra='category = "creep"\nsignature = "sig"\ntypical = "typ"\nreference = "ref"',
                       site="compliance", formula="1 + r * log10(ws / w)",
                       parameters='[parameters.r]\nunit = "1"\nstart = 0.1\nmin = -1\nmax = 1\n'
                                  'description = "creep per decade"\ntypical = [0.0, 0.5]')
    effect = effect_from_text(text, "x.toml")
    assert (effect.category, effect.signature, effect.typical, effect.reference) == ("creep", "sig", "typ", "ref")
    assert effect.params[0].typical == (0.0, 0.5) and effect.params[0].description == "creep per decade"


BAD_FILES = {
    "unknown name": (effect_text(formula="r * q"), "formula, column 5: unknown name 'q'"),
    "unknown site": (effect_text(site="voice-coil"), "site: unknown site 'voice-coil'; expected one of electrical"),
    "one bound": (effect_text(parameters='[parameters.r]\nunit = "1"\nstart = 0.5\nmin = -1'),
                  "parameters.r: expected both bounds"),
    "no bounds": (effect_text(parameters='[parameters.r]\nunit = "1"\nstart = 0.5'), "parameters.r: expected both bounds"),
    "NaN at the lines": (effect_text(formula="r / (w - w)"), "formula: gives NaN or infinity at 200 of 200 lines"),
    "infinity at the lines": (effect_text(formula="r * log(f - 1)"), "formula: gives NaN or infinity at 1 of 200 lines"),
    "not TOML": ("this is not toml\n", "not a TOML file"),
    "unknown key": (effect_text(extra='colour = "red"'), "colour: not a key of an effect file"),
    "missing key": ('id = "x"\ntitle = "t"\nsite = "electrical"\nformula = "w"\n', "physics: missing"),
    "unknown parameter key": (effect_text(parameters='[parameters.r]\nunit = "1"\nstart = 0.5\nmin = -1\nmax = 1\n'
                                                     'step = 2'), "parameters.r.step: not a key of a parameter"),
    "start outside": (effect_text(parameters='[parameters.r]\nunit = "1"\nstart = 5\nmin = -1\nmax = 1'),
                      "parameters.r.start: expected a start between"),
    "bounds reversed": (effect_text(parameters='[parameters.r]\nunit = "1"\nstart = 0\nmin = 1\nmax = -1'),
                        "parameters.r: expected min < max"),
    "bound not a number": (effect_text(parameters='[parameters.r]\nunit = "1"\nstart = 0\nmin = "low"\nmax = 1'),
                           "parameters.r.min: expected a number"),
    "infinite bound": (effect_text(parameters='[parameters.r]\nunit = "1"\nstart = 0\nmin = -inf\nmax = 1'),
                       "parameters.r.min: expected a finite number"),
    "unused parameter": (effect_text(formula="w"), "parameters.r: not used in the formula"),
    "reserved name": (effect_text(formula="w * ws", parameters='[parameters.ws]\nunit = "1"\nstart = 0\nmin = -1\nmax = 1'),
                      "parameters.ws: 'ws' is a name of the formula language"),
    "keyword name": (effect_text(formula="w", parameters='[parameters.lambda]\nunit = "1"\nstart = 0\nmin = -1\nmax = 1'),
                     "parameters.lambda: a parameter's name"),
    "bad id": (effect_text(effect_id="a,b"), "id: expected letters"),
    "id not a string": ('id = 3\ntitle = "t"\nsite = "electrical"\nformula = "w"\nphysics = "p"\n', "id: expected a non-empty string"),
}


@pytest.mark.parametrize("case", sorted(BAD_FILES))
def test_each_bad_file_is_refused_in_one_line_naming_the_file_and_the_key(case, tmp_path):
    text, words = BAD_FILES[case]
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(EffectFileError) as info:
        load_effect_file(path)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"{path}: ")
    assert words in message, message


def test_a_parameter_name_of_the_base_model_or_the_catalogue_is_refused_with_its_owner(tmp_path):
    for name, owner in (("Bl", "the base model"), ("lambda_", None), ("L2", "lr2")):
        text = effect_text(formula=f"{name} * w",
                           parameters=f'[parameters.{name}]\nunit = "1"\nstart = 0\nmin = -1\nmax = 1')
        path = tmp_path / f"{name}.toml"
        path.write_text(text, encoding="utf-8")
        if owner is None:
            assert registry.load_user_effects([path], folder=tmp_path / "none", packages=False)
            continue
        with pytest.raises(EffectFileError, match=f"parameters.{name}: .*{owner}"):
            registry.load_user_effects([path], folder=tmp_path / "none", packages=False)


def test_an_id_of_the_catalogue_or_of_another_file_is_refused(tmp_path):
    (tmp_path / "a.toml").write_text(effect_text(effect_id="lr2"), encoding="utf-8")
    with pytest.raises(EffectFileError, match="a.toml: id: 'lr2' is already an effect"):
        registry.load_user_effects([tmp_path / "a.toml"], folder=tmp_path / "none", packages=False)
    (tmp_path / "b.toml").write_text(effect_text(), encoding="utf-8")
    (tmp_path / "c.toml").write_text(effect_text(parameters='[parameters.q]\nunit = "1"\nstart = 0\nmin = -1\nmax = 1',
                                                 formula="q * w"), encoding="utf-8")
    with pytest.raises(EffectFileError, match="c.toml: id: 'mine' is already an effect"):
        registry.load_user_effects([tmp_path / "b.toml", tmp_path / "c.toml"], folder=tmp_path / "none",
                                   packages=False)


def test_an_effect_file_error_is_a_linpar_error():
    from analysis.errors import LinparError
    assert issubclass(EffectFileError, LinparError) and issubclass(EffectFileError, ValueError)


def test_missing_unreadable_and_non_regular_files_get_one_line(tmp_path):
    for path, words in ((tmp_path / "nope.toml", "no such effect file"), (tmp_path, "not a regular file")):
        with pytest.raises(EffectFileError, match=words):
            load_effect_file(path)
    binary = tmp_path / "bin.toml"
    binary.write_bytes(b"\xff\xfe\x00id")
    with pytest.raises(EffectFileError, match="not UTF-8"):
        load_effect_file(binary)


# -- where the formula acts -------------------------------------------------------------------

SITE_VALUES = {"RE": 3.02, "LE": 0.132e-3, "CMES": 433e-6, "LCES": 11.75e-3, "RES": 12.08, "Bl": 5.23}


@pytest.mark.parametrize("site, expected", [
    ("electrical", lambda F, p: F),
    ("force-factor", lambda F, p: F),
    ("mechanical", lambda F, p: F / p["Bl"] ** 2),
    ("compliance", lambda F, p: F),
    ("current", lambda F, p: 1 / F),
    ("displacement", lambda F, p: F),
])
def test_the_formula_acts_at_its_site_as_docs_physics_section_8_says(site, expected):
    effect = effect_from_text(effect_text(site=site, formula="1 + r * s / ws"), "x.toml")
    p = {**SITE_VALUES, "r": 0.3}
    ws = 1 / math.sqrt(p["CMES"] * p["LCES"])          # 2*pi*fs
    F = 1 + 0.3 * 1j * W / ws
    np.testing.assert_allclose(effect.response(1j * W, p), expected(F, p), rtol=1e-12)


def test_a_mechanical_effect_of_ones_own_needs_the_laser():
    effect = load_effect_file(EXAMPLE)
    with pytest.raises(ModelError, match="needs Bl"):
        Model((effect,), with_displacement=False)


def test_a_user_effect_travels_to_worker_processes_intact():
    effect = load_effect_file(EXAMPLE)
    copy = pickle.loads(pickle.dumps(effect))
    assert copy == effect
    p = {**SITE_VALUES, "r": 1.5}
    np.testing.assert_array_equal(copy.response(1j * W, p), effect.response(1j * W, p))


# -- the registry: folder, files, packages ------------------------------------------------------

def test_the_user_folder_is_LINPAR_EFFECTS_and_its_toml_files_are_read(tmp_path, monkeypatch):
    monkeypatch.setenv(registry.FOLDER_ENV, str(tmp_path))
    (tmp_path / "rms.toml").write_text(EXAMPLE.read_text(), encoding="utf-8")
    (tmp_path / "notes.txt").write_text("not an effect", encoding="utf-8")
    assert registry.user_folder() == tmp_path
    loaded = registry.load_user_effects(packages=False)
    assert [e.id for e in loaded] == ["rms-sqrt-f"]
    registry.register(loaded)
    assert get_effect("rms-sqrt-f") is loaded[0]
    assert [e.id for e in parse_effects("lr2,creep-log,rms-sqrt-f")] == ["lr2", "creep-log", "rms-sqrt-f"]


def test_without_LINPAR_EFFECTS_the_folder_is_in_the_platforms_configuration_folder(monkeypatch, tmp_path):
    monkeypatch.delenv(registry.FOLDER_ENV, raising=False)
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path))
    if sys.platform.startswith("linux"):
        assert registry.user_folder() == tmp_path / "linpar" / "effects"
    assert registry.user_folder().name == "effects"


def test_an_unknown_effect_says_how_to_load_ones_own():
    with pytest.raises(UnknownEffectError, match="--effects-file"):
        get_effect("rms-sqrt-f")


def test_a_package_ships_effects_through_the_linpar_effects_entry_point_group(tmp_path, monkeypatch):
    package = tmp_path / "site"
    package.mkdir()
    (package / "my_linpar_effects.py").write_text(textwrap.dedent("""
        from analysis.effects.user import effect_from_text
        EFFECT = effect_from_text('''id = "pkg-cable"
        title = "A cable"
        site = "electrical"
        formula = "rc + s * lc"
        physics = "The leads' resistance and inductance."
        [parameters.rc]
        unit = "ohm"
        start = 0.1
        min = 0
        max = 1
        [parameters.lc]
        unit = "H"
        start = 1e-6
        min = 0
        max = 1e-3
        ''', "my_linpar_effects")
    """), encoding="utf-8")
    dist = package / "my_linpar_effects-1.0.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: my-linpar-effects\nVersion: 1.0\n", encoding="utf-8")
    (dist / "entry_points.txt").write_text("[linpar.effects]\ncable = my_linpar_effects:EFFECT\n", encoding="utf-8")
    monkeypatch.syspath_prepend(str(package))
    loaded = registry.load_user_effects(folder=tmp_path / "none")
    assert [e.id for e in loaded] == ["pkg-cable"]
    registry.register(loaded)
    assert "entry point cable" in registry.source_of(loaded[0])
    (dist / "entry_points.txt").write_text("[linpar.effects]\ncable = my_linpar_effects:NOT_THERE\n", encoding="utf-8")
    with pytest.raises(EffectFileError, match="entry point cable = my_linpar_effects:NOT_THERE .*cannot be loaded"):
        registry.load_user_effects(folder=tmp_path / "none")


# -- fitting with an effect of one's own ---------------------------------------------------------

@pytest.fixture(scope="module")
def rms_data():
    effect = load_effect_file(EXAMPLE)
    truth = dict(PAPER.parameters)
    truth["r"] = truth["Bl"] ** 2 / truth["RES"]          # Rms(f) = Rms * sqrt(f / fs)
    model = Model(parse_effects("lr2,creep-log", {}) + (effect,))
    from analysis.synthesis import synthesize_recording
    from tests.builders import multitone
    mt = multitone()
    rec = synthesize_recording(model, truth, mt.waveform, mt.excited_bins, mt.sample_rate, 8, 1, TYPICAL_NOISE,
                               seed=21)
    return FitData.from_spectra(estimate_spectra(rec)), truth, effect


def _mechanical(v):
    return {"RE": v["RE"], "Bl": v["Bl"], "Mms": v["CMES"] * v["Bl"] ** 2, "Kms": v["Bl"] ** 2 / v["LCES"]}


def test_the_fit_with_the_users_effect_recovers_the_driver(rms_data):
    data, truth, effect = rms_data
    fit = fit_model(data, Model(parse_effects("lr2,creep-log") + (effect,)))
    for channel, chi2_red in fit.chi2_red_by_channel().items():
        assert chi2_red <= 1.5, channel
    fitted, true = _mechanical(fit.values), _mechanical(truth)
    for name in true:
        assert fitted[name] == pytest.approx(true[name], rel=5e-3), name
    assert (fit.values["r"] - truth["r"]) / fit.stderr["r"] == pytest.approx(0, abs=4)


def test_a_formula_that_is_not_finite_at_the_fitted_lines_stops_the_fit(rms_data):
    data, _, _ = rms_data
    line = float(data.impedance.freqs[3])
    effect = effect_from_text(effect_text(formula=f"r / (f - {line!r})"), "pole.toml")
    with pytest.raises(EffectFileError, match=r"pole.toml: formula: gives NaN or infinity at 1 of \d+ lines \(the fitted lines"):
        fit_model(data, Model(parse_effects("lr2,creep-log") + (effect,)))


def test_a_user_effect_is_a_user_effect():
    effect = load_effect_file(EXAMPLE)
    assert isinstance(effect, UserEffect) and registry.is_user_effect(effect)
    assert not registry.is_user_effect(get_effect("lr2"))


def test_asking_whether_a_built_in_effect_is_a_user_effect_imports_no_user_effect_module(monkeypatch):
    # The Model lab asks it of the candidate a first diagnosis selects, in the GUI thread: no import there.
    monkeypatch.delitem(sys.modules, "analysis.effects.user")
    assert not registry.is_user_effect(get_effect("lr2"))
    assert "analysis.effects.user" not in sys.modules
