"""piezobench.bench: experiments as arrays, checked with dsp against the bench's own truth."""

import numpy as np
import pytest

import piezobench as pb
from piezobench import bench, dsp, lti


def test_frf_noise_record_gives_the_true_resonance():
    ts = bench.simulate("frf-noise", unit=2, seed=5, duration=8.0)
    assert ts.names[:4] == ["u", "Va", "de", "Vs"] or set(["u", "de", "Vs"]) <= set(ts.names)
    assert ts.sample_rate == 10e3 and ts.samples == 80_000
    assert ts.settings["experiment"] == "frf-noise"
    est = dsp.frf(ts["u"], [ts["de"], ts["Vs"]], ts.sample_rate, outputs=["de", "Vs"], nfft=20_000)
    f = est.freq_Hz
    band = (f > 60) & (f < 150)
    peak = f[band][np.argmax(np.abs(est.H[0][band]))]
    truth = bench.truth(2, 5)
    assert peak == pytest.approx(truth.resonance_Hz, abs=1.0)
    # The linear model of the same bench agrees with the estimate at the stiffness line.
    model = bench.linear_model(2, 5)
    w = 2 * np.pi * np.array([20.0])
    h = lti.freqresp(model, w)[0, 0, 0]
    k = np.argmin(np.abs(f - 20.0))
    assert abs(est.H[0][k]) == pytest.approx(abs(h), rel=0.05)


def test_virtual_bench_run_equals_step_by_step():
    u = np.full(2000, 1.0)
    a = bench.VirtualBench(unit=1, seed=3, noise=False)
    r = a.run(u)
    b = bench.VirtualBench(unit=1, seed=3, noise=False)
    de = np.array([b.step(x)[0] for x in u])
    np.testing.assert_array_equal(r.de, de)
    assert a.effective_delay == pytest.approx(200e-6)
    # 1 V at the DAC for 0.2 s: d_e settles towards the static gain (about -17 um/V) times 1 V.
    assert r.de[-1] == pytest.approx(-17e-6, rel=0.25)
    assert bench.unit(3, 1).defective


def test_bench_results_are_the_declared_classes(declared):
    assert set(bench.declarations()) >= {"UnitTruth", "BenchRun", "TwoDofParams"}
    r = declared(bench.VirtualBench(unit=1, seed=3, noise=False).run(np.full(50, 0.5)), bench, "BenchRun")
    assert r.keys() == ["de", "vs", "va"] and all(getattr(r, k).shape == (50,) for k in r.keys())
    b = bench.VirtualBench(unit=1, seed=3, noise=False)
    np.testing.assert_array_equal(np.array([b.step(0.5) for _ in range(50)]), np.column_stack([r.de, r.vs, r.va]))
    u = declared(bench.unit(3, 1), bench, "UnitTruth")
    for k in ("id", "model", "capacitance_sensor", "capacitance_actuator", "stroke_factor", "flatness_tilt", "flatness_warp",
              "hysteresis_scale", "creep_coefficient", "load_creep_coefficient", "mode_y_Hz", "mode_x_Hz", "mode_damping",
              "defective", "defect"):
        assert k in u.keys()
    assert u.id == 3 and u.defective and u.defect and isinstance(u.capacitance_sensor, float)
    # The model is the apa.TwoDofParams class (was a dict): read by name as before, the stroke factor in ga.
    good = bench.unit(1, 1)
    assert dict(u.model)["ka"] == u.model["ka"] == u.model.ka
    assert u.stroke_factor < 0.8 < good.stroke_factor
    assert u.capacitance_sensor < 0.7 * good.capacitance_sensor  # "about half the stack capacitance" (virtual_bench.hpp)
    assert good.capacitance_sensor == pytest.approx(4.95e-6, rel=0.05)


def test_bad_experiment_and_option():
    with pytest.raises(pb.InputError) as e:
        bench.simulate("frf-nois")
    assert e.value.field == "experiment"
    with pytest.raises(pb.InputError) as e:
        bench.simulate("stroke", durations=3.0)
    assert e.value.field == "durations"
