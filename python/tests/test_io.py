"""piezobench.io against files written and read by scipy.io (MATLAB layout) and numpy (CSV)."""

import numpy as np
import pytest
import scipy.io

import piezobench as pb
from piezobench import dsp, io


def test_reads_a_mat_file_written_by_scipy(tmp_path):
    fs = 1000.0
    t = np.arange(500) / fs
    u = np.sin(2 * np.pi * 10 * t)
    de = 1e-6 * np.cos(2 * np.pi * 10 * t)
    f = tmp_path / "rec.mat"
    scipy.io.savemat(f, {"t": t[:, None], "u": u[:, None], "de": de[None, :]})
    ts = io.read_timeseries(str(f), channels=["u", "de"])
    assert ts.names == ["u", "de"] and ts.sample_rate == pytest.approx(fs, rel=1e-9)
    np.testing.assert_array_equal(ts["u"], u)
    np.testing.assert_array_equal(ts.channel("de"), de)
    np.testing.assert_array_equal(ts.t, t)
    assert ts.data.shape == (500, 2) and not ts.data.flags.writeable
    with pytest.raises(pb.InputError) as e:
        io.read_timeseries(str(f), channels=["Vs"])
    assert "Vs" in str(e.value) and str(f) in str(e.value)


def test_written_files_read_back_by_scipy_and_numpy(tmp_path):
    rng = np.random.default_rng(4)
    ts = io.TimeSeries({"u": rng.standard_normal(300), "Vs": rng.standard_normal(300)}, 2000.0,
                       units={"u": "V", "Vs": "V"}, settings={"experiment": "frf-noise", "seed": 4})
    mat = tmp_path / "out.mat"
    io.write_timeseries(ts, str(mat))
    m = scipy.io.loadmat(mat, squeeze_me=True)
    np.testing.assert_array_equal(m["u"], ts["u"])
    np.testing.assert_array_equal(m["Vs"], ts["Vs"])
    assert float(m["fs"]) == 2000.0
    back = io.read_timeseries(str(mat))
    assert back.settings["experiment"] == "frf-noise" and back.units["Vs"] == "V"
    csv = tmp_path / "out.csv"
    io.write_timeseries(ts, str(csv))
    data = np.loadtxt(csv, delimiter=",", comments="#", skiprows=2)
    np.testing.assert_array_equal(data[:, 0], ts["u"])
    with pytest.raises(pb.InputError) as e:
        io.write_timeseries(ts, str(mat), version="v8")
    assert e.value.field == "version"


def test_frf_files_round_trip(tmp_path):
    f = np.linspace(1.0, 100.0, 100)
    h = 1.0 / (1.0 + 1j * f / 30.0)
    frf = dsp.Frf(f, np.vstack([h, 2 * h]), outputs=["de", "Vs"], coherence=np.ones((2, 100)))
    for ext in ("csv", "mat", "uff"):
        path = tmp_path / f"frf.{ext}"
        io.write_frf(frf, str(path))
        back = io.read_frf(str(path))
        assert back.outputs == ["de", "Vs"]
        tol = 1e-12 if ext != "uff" else 1e-11
        np.testing.assert_allclose(back.H, frf.H, rtol=tol)
    # CSV in the documented layout, written by numpy.
    path = tmp_path / "numpy.csv"
    np.savetxt(path, np.column_stack([f, h.real, h.imag]), delimiter=",", header="freq_Hz,re_x,im_x", comments="")
    back = io.read_frf(str(path))
    assert back.outputs == ["x"]
    np.testing.assert_allclose(back.H, h, rtol=1e-15)
