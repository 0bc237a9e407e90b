"""piezobench.apa: the 2-DoF model's closed forms (docs/models.md), tuning on exact FRFs, eq. 4.1."""

import numpy as np
import pytest

import piezobench as pb
from piezobench import apa, dsp, lti


def test_two_dof_static_gains_and_zeros_match_the_closed_forms():
    p = apa.default_params()
    c = apa.characterize()
    k_tot = p["k1"] + p["ke"] * p["ka"] / (p["ke"] + p["ka"])
    g = 20.0
    assert c.static_gain_de == pytest.approx(g * p["ga"] * p["ke"] / (p["ke"] + p["ka"]) / k_tot, rel=1e-10)
    assert c.static_gain_de == pytest.approx(-16.81e-6, rel=1e-3)   # report: -16.81 um/V
    assert c.static_gain_vs == pytest.approx(0.588, rel=1e-3)
    assert c.antiresonance / (2 * np.pi) == pytest.approx(np.sqrt(p["k1"] / p["m"]) / (2 * np.pi), rel=1e-6)
    # The closed-form response equals the state space's.
    w = 2 * np.pi * np.logspace(0, 3, 50)
    sys = apa.two_dof_bench(delay=1e-4)
    h = lti.freqresp(sys, w)
    np.testing.assert_allclose(apa.two_dof_response(w, delay=1e-4), h[:, :, 0], rtol=1e-9)
    with pytest.raises(pb.InputError) as e:
        apa.two_dof_bench(k2=3.0)
    assert e.value.field == "k2"


def test_tuning_recovers_the_parameters_from_exact_frfs():
    true = dict(apa.default_params(), k1=0.4e6, ga=-2.4)
    f = np.linspace(1.0, 2000.0, 2000)
    h = apa.two_dof_response(2 * np.pi * f, **true)
    frf = dsp.Frf(f, h.T, outputs=["de", "Vs"])
    r = apa.tune_two_dof(frf)
    assert r.status == "converged"
    for name in ("k1", "ka", "ke", "ga", "gs"):
        assert r.params[name] == pytest.approx(true[name], rel=1e-3), name
    assert r.fit_error_de < 1e-4
    # The tuning is apa.TwoDofTuning, from its declaration (apa/tuning.hpp): every declared field an
    # attribute; the parameters a class that reads like the dict it replaced.
    assert isinstance(r, apa.TwoDofTuning) and isinstance(r.params, apa.TwoDofParams)
    assert [f[0] for f in apa.TwoDofTuning.fields()] == list(apa.TwoDofTuning.keys())
    assert all(hasattr(r, name) for name in apa.TwoDofTuning.keys())
    assert dict(r.params)["k1"] == r.params.k1 == r.params["k1"]
    assert r.features.resonance > 0 and r.brief_report.startswith("2-DoF tuning: converged")


def test_piezo_sensitivities_table_4_1():
    s = apa.piezo_sensitivities()
    assert s.ka == pytest.approx(48e9 * 1e-4 / 20e-3, rel=1e-12)
    assert s.ga == pytest.approx(26.11, rel=1e-3)
    assert s.gs == pytest.approx(5.06e6, rel=1e-3)
    with pytest.raises(pb.InputError) as e:
        apa.piezo_sensitivities(layers=2.5)
    assert e.value.field == "layers"


def test_measured_tuning_of_a_scipy_welch_frf_with_only_the_mass(welch_frf):
    """As `piezobench model tune --frf two_dof_welch_frf.csv --mass 5.7` (tests/app/model_cli_test.cpp):
    the plant fits give the delay and the high-pass, the tuning finds the simulation's parameters."""
    from piezobench import ident
    frf, truth = welch_frf
    plants = ident.fit_actuator_plants(frf, min_coherence=0.5)
    r = apa.tune_two_dof_measured(frf, plants.de, plants.vs, mass=5.7, fmin_Hz=20.0, fmax_Hz=500.0, min_coherence=0.5)
    for name in ("k1", "ke", "ka", "ga", "gs"):
        assert r.params[name] == pytest.approx(truth[name], rel=0.03), name
    # The shell's damping c1 does not show in this FRF: reported undetermined, so the verdict is poor
    # (issue 30: never a confident wrong value); the standard errors are there.
    assert r.undetermined == ["c1"] and r.quality.verdict == "poor" and not r.quality.impossible
    assert r.uncertainty.standard_error_of("k1") > 0
    assert r.bench["delay"] == pytest.approx(truth["effective_delay_s"], rel=0.05)
    corner_Hz = 1 / (2 * np.pi * r.bench["hpf_resistance"] * r.bench["hpf_capacitance"])
    assert corner_Hz == pytest.approx(truth["hpf_corner_Hz"], rel=0.1)
    # A 2 ms delay instead of the fitted 0.25 ms leaves no model that fits: a poor verdict, with advice.
    bad = apa.tune_two_dof_measured(frf, None, plants.vs, mass=5.7, fmin_Hz=20.0, fmax_Hz=500.0, min_coherence=0.5,
                                    bench={"delay": 0.002})
    assert bad.quality.poor and bad.quality.problems
    with pytest.raises(pb.InputError) as e:
        apa.tune_two_dof_measured(frf, plants.vs, None)
    assert e.value.field == "de_plant"
