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


def test_piezo_sensitivities_table_4_1():
    s = apa.piezo_sensitivities()
    assert s.ka == pytest.approx(48e9 * 1e-4 / 20e-3, rel=1e-12)
    assert s.ga == pytest.approx(26.11, rel=1e-3)
    assert s.gs == pytest.approx(5.06e6, rel=1e-3)
    with pytest.raises(pb.InputError) as e:
        apa.piezo_sensitivities(layers=2.5)
    assert e.value.field == "layers"
