"""Hysteresis and creep from Python: identification, the exact inverse, the feedforward, the model
file and the tracking experiment on the Bouc-Wen bench."""

import numpy as np
import pytest

import piezobench as pb
from piezobench import bench, control, ident, io


def _record():
    t = np.arange(0, 4.0, 1e-3)
    va = np.where(t < 1, 65 * t, 65 + 80 * np.sin(2 * np.pi * (t - 1)))
    return va


def test_inverse_composed_with_the_operator_is_the_identity():
    rng = np.random.default_rng(3)
    r = np.cumsum(rng.uniform(1, 20, 8))
    w = rng.uniform(0, 0.6, 8)
    v = np.cumsum(rng.normal(0, 5, 3000))
    y = ident.prandtl_ishlinskii(v, r, w)
    g = ident.inverse_prandtl_ishlinskii(r, w)
    assert isinstance(g, ident.PrandtlIshlinskii)
    # Its thresholds are H's initial loading curve at r_i: r'_i = r_i + sum_{j<i} w_j (r_i - r_j).
    expected = [r[i] + sum(w[j] * (r[i] - r[j]) for j in range(i)) for i in range(len(r))]
    np.testing.assert_allclose(g.thresholds, expected, rtol=1e-12)
    back = ident.prandtl_ishlinskii(y, g.thresholds, g.weights, g.linear_weight)
    np.testing.assert_allclose(back, v, atol=1e-9)


def test_fit_recovers_a_prandtl_ishlinskii_record_and_the_feedforward_linearizes_it(tmp_path):
    va = _record()
    n, R = 10, 80.0
    r = (np.arange(n) + 0.5) * R / n
    w = np.array([0.05, 0.2, 0.0, 0.1, 0.1, 0.0, 0.05, 0.0, 0.02, 0.0])
    de = 1e-7 - 1.5e-6 * ident.prandtl_ishlinskii(va, r, w)
    fit = ident.fit_hysteresis(va, de, 1000.0, operators=n)
    # The declared ident.HysteresisFit: its model's PI operator (model.hysteresis) is the record's.
    assert isinstance(fit, ident.HysteresisFit) and isinstance(fit.model, ident.HysteresisModel)
    assert fit.quality.verdict == "good" and fit.relative_residual < 1e-9 and fit.samples == len(va)
    assert fit.stroke == pytest.approx(de.max() - de.min(), rel=1e-12)
    assert fit.rms_residual == pytest.approx(fit.relative_residual * fit.stroke, rel=1e-9)
    np.testing.assert_allclose(fit.model.hysteresis.thresholds, r, rtol=1e-12)
    np.testing.assert_allclose(fit.model.hysteresis.weights, w, atol=1e-7)
    assert fit.model.gain == pytest.approx(-1.5e-6, rel=1e-9)
    assert fit.model.offset == pytest.approx(1e-7, rel=1e-6)
    assert fit.model.input_min == va.min() and fit.model.input_max == va.max()
    assert len(fit.model.output.x) == 0  # the plain PI: the identity output map
    c = _record()
    applied = control.hysteresis_feedforward(fit.model, c, 1000.0)
    d = ident.predict_hysteresis(fit.model, applied, 1000.0)
    m = fit.model
    np.testing.assert_allclose(d, m.offset + m.gain * (m.reference_slope * c + m.reference_intercept), atol=1e-12)
    assert ident.loop_metrics(c, d).width < 1e-9
    loop = ident.loop_metrics(va, de)
    assert isinstance(loop, ident.LoopMetrics) and loop.width > 0.1
    slope, intercept = np.polyfit(va, de, 1)  # the best line, by numpy
    assert loop.slope == pytest.approx(slope, rel=1e-9) and loop.intercept == pytest.approx(intercept, rel=1e-6)
    assert loop.stroke == pytest.approx(de.max() - de.min(), rel=1e-12)
    dev = de - (slope * va + intercept)
    assert loop.rms_deviation == pytest.approx(np.sqrt(np.mean(dev**2)), rel=1e-6)
    assert loop.width == pytest.approx((dev.max() - dev.min()) / loop.stroke, rel=1e-6)
    path = tmp_path / "model.toml"
    io.write_hysteresis_model(str(path), fit.model)
    back = io.read_hysteresis_model(str(path))
    assert isinstance(back, ident.HysteresisModel)
    np.testing.assert_array_equal(back.hysteresis.weights, fit.model.hysteresis.weights)
    assert back.gain == fit.model.gain


def test_bad_models_and_records_name_the_field():
    with pytest.raises(pb.InputError) as e:
        ident.inverse_prandtl_ishlinskii([5.0, 4.0], [0.1, 0.1])
    assert e.value.field == "thresholds[1]"
    with pytest.raises(pb.InputError) as e:
        control.hysteresis_feedforward({"thresholds": [1.0], "weights": [0.1]}, [0.0, 1.0], 1e3)
    assert e.value.field == "model.gain"
    with pytest.raises(pb.InputError) as e:
        control.hysteresis_feedforward([1.0, 2.0], [0.0, 1.0], 1e3)
    assert e.value.field == "model"
    with pytest.raises(pb.InputError):
        ident.fit_hysteresis([1.0] * 20, [0.0] * 20, 1e3)


def test_creep_fit_of_a_step():
    fs = 100.0
    x = np.zeros(6000)
    x[300:4000] = 1.0
    a = -np.expm1(-1 / (fs * np.array([1.0, 10.0])))
    f = np.zeros((6000, 2))
    s = np.zeros(2)
    for k in range(6000):
        f[k] = s
        s = s + a * (x[k] - s)
    y = 2e-6 * (x + f @ [0.05, 0.1])
    c = ident.fit_creep(x, y, fs, [1.0, 10.0])
    assert isinstance(c, ident.CreepFit) and c.quality.verdict == "good"
    np.testing.assert_allclose(c.time_constants, [1.0, 10.0])
    np.testing.assert_allclose(c.coefficients, [0.05, 0.1], atol=1e-7)
    assert c.gain == pytest.approx(2e-6, rel=1e-6) and c.offset == pytest.approx(0.0, abs=1e-12)
    assert c.creep_per_decade == pytest.approx(np.mean(c.coefficients), rel=1e-12)
    assert c.relative_residual < 1e-6


def test_tracking_on_the_bouc_wen_bench():
    ts = bench.simulate("tracking", unit=2, seed=1, hysteresis_law="bouc-wen")
    s = ts.settings
    assert s["width_open_sine"] > 0.15
    assert s["width_ff_sine"] < 0.03
    assert s["rms_open_sine_m"] / s["rms_ff_sine_m"] >= 5
    with pytest.raises(pb.InputError) as e:
        bench.simulate("tracking", hysteresis_law="preisach")
    assert e.value.field == "hysteresis_law"


def test_the_asymmetric_bench_law_bends_the_loop():
    # The bench's third law: its 80 V loop is asymmetric, the two symmetric laws' are not.
    def asymmetry(law):
        ts = bench.simulate("hysteresis", unit=1, seed=1, amplitude=80.0, hysteresis_law=law)
        va, de = ts.channel("Va"), ts.channel("de")
        fs = ts.sample_rate
        steady = slice(int(1.25 * fs), int(3.25 * fs))  # from the first to the last maximum of Va
        return ident.loop_metrics(va[steady], de[steady]).asymmetry

    assert asymmetry("bouc-wen-asymmetric") > 0.015
    assert asymmetry("bouc-wen") < 0.002


def test_modified_prandtl_ishlinskii_fits_an_asymmetric_loop_and_its_feedforward_linearizes_it():
    # A PI loop seen through an asymmetric smooth output (not a dead-zone superposition).
    va = _record()
    r = (np.arange(10) + 0.5) * 8.0
    x = ident.prandtl_ishlinskii(va, r, np.full(10, 0.06))
    de = -1e-6 * (x + 0.006 * x**2)
    plain = ident.fit_hysteresis(va, de, 1000.0)
    mod = ident.fit_hysteresis(va, de, 1000.0, dead_zones=4)
    assert plain.quality.verdict == "poor" and mod.quality.verdict == "good"
    assert plain.quality.problems and plain.quality.advice
    assert len(mod.model.output.x) == 9 and len(mod.model.output.y) == 9
    assert np.all(np.diff(mod.model.output.x) > 0) and np.all(np.diff(mod.model.output.y) > 0)
    d = ident.predict_hysteresis(mod.model, control.hysteresis_feedforward(mod.model, va, 1000.0), 1000.0)
    m = mod.model
    np.testing.assert_allclose(d, m.offset + m.gain * (m.reference_slope * va + m.reference_intercept), atol=1e-12)
