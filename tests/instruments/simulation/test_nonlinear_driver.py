"""NonlinearBlockDriver: the linear model at small signal, a softening driver at large signal, streaming."""
import numpy as np
import pytest

from analysis.drivers import load_driver
from analysis.multitone import design_multitone
from analysis.pipeline import analyze_recording
from analysis.recording.format import make_recording
from analysis.synthesis import steady_state_period
from instruments.simulation.block_driver import BlockDriver
from instruments.simulation.nonlinear_driver import NonlinearBlockDriver

PAPER = load_driver("paper")
FS, N = 48000, 8192
MT = design_multitone(FS, N, 5.0, 10000.0, rms=1.0, crest_iterations=10)


def _steady(driver, rms, periods=4):
    """The last period after `periods` (the FIR spans one period, so two settle it)."""
    driver.reset()
    block = driver.process(MT.scaled(rms=rms).tile(periods))
    return block.current[-N:], block.displacement[-N:]


def test_it_is_a_block_driver_whose_blocks_are_read_only():
    driver = NonlinearBlockDriver(PAPER.parameters, FS, fir_length=N)
    assert isinstance(driver, BlockDriver)
    block = driver.process(np.zeros(100))
    assert len(block) == 100 and not block.current.flags.writeable and not block.displacement.flags.writeable
    assert len(driver.process(np.zeros(0))) == 0


def test_at_a_tiny_level_it_is_the_linear_model_of_the_paper():
    driver = NonlinearBlockDriver(PAPER.parameters, FS, fir_length=N)
    current, displacement = _steady(driver, 1e-3)
    ref = steady_state_period(PAPER.model(), PAPER.parameters, MT.scaled(rms=1e-3).waveform, MT.excited_bins, FS)
    assert np.max(np.abs(current - ref["current"])) < 1e-4 * np.max(np.abs(ref["current"]))
    assert np.max(np.abs(displacement - ref["displacement"])) < 1e-5 * np.max(np.abs(ref["displacement"]))


def test_with_flat_polynomials_it_is_linear_at_any_level():
    driver = NonlinearBlockDriver(PAPER.parameters, FS, bl_poly=(), kms_poly=(), le_poly=(), fir_length=N)
    current, displacement = _steady(driver, 10.0)
    ref = steady_state_period(PAPER.model(), PAPER.parameters, MT.scaled(rms=10.0).waveform, MT.excited_bins, FS)
    np.testing.assert_allclose(current, ref["current"], atol=1e-9 * np.max(np.abs(ref["current"])))
    np.testing.assert_allclose(displacement, ref["displacement"], atol=1e-9 * np.max(np.abs(ref["displacement"])))


def test_the_deviation_from_linear_grows_with_level():
    driver = NonlinearBlockDriver(PAPER.parameters, FS, fir_length=N)
    deviations = []
    for rms in (0.1, 1.0, 10.0):
        _, x = _steady(driver, rms)
        ref = steady_state_period(PAPER.model(), PAPER.parameters, MT.scaled(rms=rms).waveform, MT.excited_bins, FS)
        deviations.append(np.max(np.abs(x - ref["displacement"])) / np.max(np.abs(ref["displacement"])))
    assert deviations[0] < 1e-3 < deviations[2]
    assert deviations[0] < deviations[1] < deviations[2]


def test_a_stream_cut_into_blocks_gives_the_same_samples():
    driver = NonlinearBlockDriver(PAPER.parameters, FS, fir_length=N, partition_size=256)
    u = MT.scaled(rms=5.0).tile(2)
    whole = driver.process(u)
    driver.reset()
    cuts = [0, 1, 300, 301, 4096, 9000, u.size]
    parts = [driver.process(u[a:b]) for a, b in zip(cuts[:-1], cuts[1:])]
    np.testing.assert_allclose(np.concatenate([p.current for p in parts]), whole.current, rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.concatenate([p.displacement for p in parts]), whole.displacement,
                               rtol=0, atol=1e-15)


def test_the_curves_start_at_the_paper_values_and_soften():
    driver = NonlinearBlockDriver(PAPER.parameters, FS, fir_length=N)
    p = PAPER.parameters
    assert driver.bl(0.0) == pytest.approx(p["Bl"])
    assert driver.kms(0.0) == pytest.approx(p["Bl"] ** 2 / p["LCES"])
    assert driver.le(0.0) == pytest.approx(p["LE"])
    assert driver.kms(5e-3) < driver.kms(0.0) and driver.bl(5e-3) < driver.bl(0.0)
    assert driver.le(-3e-3) > driver.le(0.0) > driver.le(3e-3)      # more inductance with the coil in


def test_at_large_excursion_fs_falls_and_cms_rises_like_the_papers_driver():
    """docs/physics.md section 6: fs 70.5 -> 57.1 Hz, Cms +50 % from 0.17 mm to 8.6 mm peak.

    With the project's standard multitone (16,384 samples, 5 Hz - 10 kHz), as the defaults' comment says.
    """
    n = 16384
    mt = design_multitone(FS, n, 5.0, 10000.0, rms=1.0)
    driver = NonlinearBlockDriver(PAPER.parameters, FS, fir_length=n)
    rng = np.random.default_rng(0)
    fitted = {}
    for rms in (0.33, 14.0):
        driver.reset()
        block = driver.process(mt.scaled(rms=rms).tile(5))
        signals = {"voltage": block.voltage, "current": block.current + rng.normal(0, 1e-4, block.current.size),
                   "displacement": block.displacement + rng.normal(0, 1e-8, block.current.size)}
        rec = make_recording(FS, signals, n, settle_periods=2, excited_bins=tuple(int(b) for b in mt.excited_bins))
        result = analyze_recording(rec)
        fitted[rms] = (result.parameters["fs"].value, result.parameters["Cms"].value,
                       result.validity.peak_displacement_m)
    (fs_small, cms_small, peak_small), (fs_large, cms_large, peak_large) = fitted[0.33], fitted[14.0]
    assert peak_small == pytest.approx(0.17e-3, rel=0.1) and peak_large == pytest.approx(8.5e-3, rel=0.05)
    assert fs_small == pytest.approx(70.5, abs=0.3)
    assert fs_large == pytest.approx(58.0, abs=1.5)
    assert cms_large / cms_small == pytest.approx(1.53, abs=0.1)


@pytest.mark.parametrize("kwargs, words", [
    ({"kms_poly": (0.0, -2e4)}, "Kms"),            # Kms(x) = K0 (1 - 2e4 x^2) < 0 beyond 7 mm
    ({"bl_poly": (0.0, 0.0, 0.0, 0.0, 1.0)}, "at most 4"),
    ({"le_poly": (-80.0,)}, "Le"),                 # too steep for the explicit step
])
def test_shapes_that_cannot_be_simulated_are_refused(kwargs, words):
    with pytest.raises(ValueError, match=words):
        NonlinearBlockDriver(PAPER.parameters, FS, fir_length=N, **kwargs)


def test_values_without_the_electrical_analogues_are_refused():
    with pytest.raises(ValueError, match="RES"):
        NonlinearBlockDriver({k: v for k, v in PAPER.parameters.items() if k != "RES"}, FS)


# --- the terms a large-signal identification claims: L2(x), Le(i), Rms(v); and the substeps -------------------

ALL_TERMS = dict(bl_poly=(-30.0, -1e4), kms_poly=(40.0, 5e4), le_poly=(-10.0,), l2_poly=(-30.0, 2e3),
                 le_i_poly=(0.0, -0.003), rms_v2=0.1, i_range_a=5.0, x_range_m=0.008)


def _sine_period(driver, k, amplitude, n=4096, periods=6):
    driver.reset()
    u = amplitude * np.sin(2 * np.pi * k * np.arange(n) / n)
    block = driver.process(np.tile(u, periods))
    return u, block.current[-n:], block.displacement[-n:]


def test_with_flat_curves_and_substeps_it_is_still_the_linear_model():
    driver = NonlinearBlockDriver(PAPER.parameters, FS, bl_poly=(), kms_poly=(), le_poly=(), fir_length=N,
                                  substeps=4)
    current, displacement = _steady(driver, 10.0)
    ref = steady_state_period(PAPER.model(), PAPER.parameters, MT.scaled(rms=10.0).waveform, MT.excited_bins, FS)
    np.testing.assert_allclose(current, ref["current"], atol=1e-9 * np.max(np.abs(ref["current"])))
    np.testing.assert_allclose(displacement, ref["displacement"], atol=1e-9 * np.max(np.abs(ref["displacement"])))


@pytest.mark.parametrize("term", [{"l2_poly": (-30.0, 2e3)}, {"le_i_poly": (0.0, -0.003)}, {"rms_v2": 0.1}])
def test_each_new_term_changes_the_large_signal_and_not_the_small_signal(term):
    common = dict(fir_length=N, i_range_a=5.0, le_poly=(-10.0,), x_range_m=0.008)
    plain = NonlinearBlockDriver(PAPER.parameters, FS, **common)
    other = NonlinearBlockDriver(PAPER.parameters, FS, **common, **term)
    for rms, changed in ((1e-3, False), (8.0, True)):
        a, b = _steady(plain, rms)[0], _steady(other, rms)[0]
        deviation = np.max(np.abs(a - b)) / np.max(np.abs(a))
        assert (deviation > 1e-4) == changed, (term, rms, deviation)


def test_the_time_steps_agree_with_the_periodic_steady_state_of_the_same_equations():
    """Two solvers of the module's equations, written apart: this ETD2 stepper and analysis.large_signal's
    harmonic balance. Every term on; H2 and H3 of current and displacement, and the cone's mean shift."""
    from analysis.large_signal.simulate import steady_state
    from tests.large_signal_truth import truth_model
    no_creep = {k: v for k, v in PAPER.parameters.items() if k != "lambda"}     # see truth_model
    driver = NonlinearBlockDriver(no_creep, FS, fir_length=4096, substeps=4, **ALL_TERMS)
    model = truth_model(driver)
    for k, amplitude in ((2, 5.0), (4, 8.0), (20, 10.0)):
        u, current, displacement = _sine_period(driver, k, amplitude)
        periodic = steady_state(model, u, FS)
        for measured, solved in ((current, periodic.current), (displacement, periodic.displacement)):
            a, b = np.abs(np.fft.rfft(measured)), np.abs(np.fft.rfft(solved))
            for h in (2, 3):
                assert 20 * np.log10(a[h * k] / b[h * k]) == pytest.approx(0.0, abs=0.05), (k, h)
        assert np.mean(displacement) == pytest.approx(np.mean(periodic.displacement), rel=0.01, abs=1e-7)


@pytest.mark.parametrize("kwargs, words", [
    ({"l2_poly": (-30.0,), "values": "no LR-2"}, "eddy branch"),
    ({"le_i_poly": (0.0, -0.05), "i_range_a": 10.0}, "incremental inductance"),
    ({"substeps": 0}, "substeps"),
    ({"rms_v2": -1.0}, "rms_v2"),
])
def test_new_terms_that_cannot_be_simulated_are_refused(kwargs, words):
    values = dict(PAPER.parameters)
    if kwargs.pop("values", None):
        values = {k: v for k, v in values.items() if k not in ("L2", "R2")}
    with pytest.raises(ValueError, match=words):
        NonlinearBlockDriver(values, FS, fir_length=N, **kwargs)
