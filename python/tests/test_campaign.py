"""piezobench.campaign: a short demo campaign written and run from Python, its typed results
checked against the virtual bench's truth (as tests/campaign/demo_test.cpp does in C++) and against
the results.json that the command line (`piezobench run`) writes for the same campaign."""

import json
import os
import subprocess

import numpy as np
import pytest

import piezobench as pb
from piezobench import campaign, ident


def _cli():
    """The piezobench command of the same build (ctest sets PIEZOBENCH_CLI)."""
    path = os.environ.get("PIEZOBENCH_CLI") or os.path.join(os.path.dirname(__file__), "..", "..", "build", "app",
                                                             "piezobench")
    return path if os.path.exists(path) else None


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("demo")
    files = campaign.write_demo(str(tmp), fast=True, units=[1], iff_gains=[60e3, 120e3])
    return tmp, files, campaign.run(files.campaign, out_dir=str(tmp / "out"))


def test_write_demo_returns_the_declared_demo_files(demo, declared):
    tmp, files, _ = demo
    cls, fields = campaign.declarations()["DemoFiles"]
    assert fields == ["campaign", "truth", "superelement", "data"]
    declared(files, campaign, "DemoFiles")
    assert files.campaign == str(tmp / "campaign.toml") and files.truth == str(tmp / "data" / "truth.json")
    assert all(isinstance(p, str) and os.path.exists(p) for p in [files.campaign, files.truth, files.superelement] + files.data)
    assert files.data and all(p.startswith(str(tmp)) for p in files.data)


def test_demo_campaign_results_agree_with_the_truth(demo):
    tmp, files, r = demo
    truth = json.loads(open(files.truth).read())["units"][0]
    assert isinstance(r, campaign.CampaignResult)
    unit = r.units[0]
    assert isinstance(unit, campaign.UnitAnalysis)
    assert unit.id == 1 and unit.accepted and unit.reasons == [] and r.accepted == 1 and r.rejected == 0
    assert unit.resonance_Hz == pytest.approx(truth["resonance_Hz"], rel=0.01)
    assert unit.antiresonance_Hz == pytest.approx(truth["antiresonance_Hz"], rel=0.01)
    # Issue 30: the truth, or undetermined (None) when the 95 % interval of xz contains 0; never wrong.
    assert unit.frf_analysis.zero_is_nonminimum_phase in (truth["zero_is_nonminimum_phase"], None)
    nmp = unit.frf_analysis.nmp  # which evidence decided, and why (ident::zero_phase_verdict)
    assert nmp.verdict_from == "iff-plant-fit" and nmp.verdict_reason.startswith("plant fit zero xz = ")
    assert nmp.iff_plant_fit_xz_standard_error > 0
    assert unit.k1 * 1e-6 == pytest.approx(truth["stiffness_N_per_um"]["k1"], rel=0.05)
    # The IFF plant of the unit is an ident.IffPlantFit with its verdict, as ident.fit_iff_plant returns.
    assert isinstance(unit.iff_plant, ident.IffPlantFit) and unit.iff_plant.quality.verdict == "good"
    assert unit.iff_plant.zero_is_nonminimum_phase
    # results.json stays available as Results (the earlier interface) and as plain dicts.
    assert r.results.units[0].frf.resonance_Hz == unit.resonance_Hz
    on_disk = json.loads((tmp / "out" / "results.json").read_text())
    d = r.to_dict()
    assert d["units"][0]["frf"]["resonance_Hz"] == on_disk["units"][0]["frf"]["resonance_Hz"]
    assert isinstance(d["units"][0], dict) and isinstance(d["iff"], dict)  # plain data
    assert unit.json().frf.resonance_Hz == unit.resonance_Hz
    assert any(p.endswith("report.html") for p in r.written)
    # Read-only, with to_dict() on every typed class.
    with pytest.raises(AttributeError):
        unit.k1 = 1.0
    u = unit.to_dict()
    assert u["k1"] == unit.k1 and u["frf_analysis"]["hpf"]["corner_Hz"] == unit.frf_analysis.hpf.corner_Hz
    assert r.unit(1).id == 1
    # The tracking record of the demo's unit 1: the inverse feedforward of the unit's hysteresis model.
    t = unit.tracking
    assert isinstance(t, campaign.TrackingAnalysis) and t.feedforward == "given" and t.amplitude == 80.0
    assert t.sine.width_open > 0.15 and t.sine.width_ff < 0.03 and t.sine.rms_reduction >= 5.0
    assert t.triangle.rms_ff * 1e6 == pytest.approx(d["units"][0]["tracking"]["triangle"]["rms_ff_um"], rel=1e-12)
    assert len(t.sine_open.x) == len(t.sine_ff.y) > 100
    with pytest.raises(pb.InputError) as e:
        r.unit(7)
    assert e.value.field == "id"


def test_typed_results_equal_the_results_json_of_the_command_line(demo):
    cli = _cli()
    if cli is None:
        pytest.skip("the piezobench command is not built (set PIEZOBENCH_CLI)")
    tmp, files, r = demo
    out = tmp / "cli"
    p = subprocess.run([cli, "run", files.campaign, "--out", str(out)], capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    j = json.loads((out / "results.json").read_text())
    ju = j["units"][0]
    u = r.units[0]
    # Per unit (SI in Python, the report's units in results.json).
    assert ju["id"] == u.id and ju["name"] == u.name and ju["accepted"] == u.accepted and ju["reasons"] == u.reasons
    same = lambda a, b: a == pytest.approx(b, rel=1e-12, abs=0.0)  # noqa: E731
    assert same(u.k1 / 1e6, ju["stiffness_N_per_um"]["k1"])
    assert same(u.k2 / 1e6, ju["stiffness_N_per_um"]["k2"])
    assert same(u.k_oc / 1e6, ju["stiffness_N_per_um"]["k_oc"])
    assert same(u.k_resonance / 1e6, ju["stiffness_N_per_um"]["resonance"])
    assert same(u.flatness * 1e6, ju["flatness_um"])
    assert same(u.stroke * 1e6, ju["stroke_um"])
    assert same(u.capacitance_sensor * 1e6, ju["capacitance_uF"]["sensor"])
    assert same(u.capacitance_actuator * 1e6, ju["capacitance_uF"]["actuator"])
    assert same(u.resonance_Hz, ju["frf"]["resonance_Hz"])
    assert same(u.antiresonance_Hz, ju["frf"]["antiresonance_Hz"])
    assert same(u.static_gain * 1e6, ju["frf"]["static_gain_um_per_V"])
    assert same(u.frf_analysis.hpf.corner_Hz, ju["hpf_corner_Hz"])
    params = u.model_2dof.tuning.params
    for name in ("k1", "ke", "ka", "ga", "gs", "m"):
        assert same(params[name], ju["model_2dof"][name]), name
    # The batch summary.
    assert r.accepted == j["summary"]["accepted"] and r.rejected == j["summary"]["rejected"]
    for s in r.batch.spread:
        js = j["batch"]["spread"][s.quantity]
        assert s.units == js["units"]
        for field in ("min", "max", "median", "relative_spread", "mad"):
            assert same(getattr(s, field), js[field]), (s.quantity, field)
    assert sorted(s.quantity for s in r.batch.spread) == sorted(j["batch"]["spread"])
    k1 = r.batch.spread_of("k1_N_per_um")
    assert isinstance(k1, campaign.QuantitySpread) and k1.unit == "N/um" and same(k1.median, u.k1 / 1e6)
    assert r.batch.spread_of("no_such_quantity") is None
    assert [(o.unit, o.quantity) for o in r.batch.outliers] == [(o["unit"], o["quantity"]) for o in j["batch"]["outliers"]]
    for o, jo in zip(r.batch.outliers, j["batch"]["outliers"]):
        assert same(o.value, jo["value"]) and same(o.median, jo["median"]) and same(o.robust_z, jo["robust_z"])
    rule = j["batch"]["outlier_rule"]
    assert r.batch.rejects == rule["rejects"] and same(r.batch.rule.threshold, rule["robust_z_threshold"])
    assert same(r.batch.rule.min_relative_deviation, rule["min_relative_deviation"])
    # The IFF study.
    iff, ji = r.iff, j["iff"]
    assert iff.unit == ji["unit"]
    np.testing.assert_allclose(iff.gains, ji["gains"], rtol=1e-12)
    np.testing.assert_allclose(iff.damped_poles, [complex(*p) for p in ji["damped_poles"]], rtol=1e-12)
    np.testing.assert_allclose(iff.model_poles, [complex(*p) for p in ji["model_poles"]], rtol=1e-12)
    assert same(iff.optimal_gain, ji["optimal_gain"]) and same(iff.max_damping, ji["max_damping"])
    assert same(iff.optimal_pole, complex(*ji["optimal_pole"]))
    assert same(iff.max_relative_pole_distance, ji["max_relative_pole_distance"])
    assert same(iff.plant.wz_Hz, ji["plant"]["wz_Hz"]) and same(iff.plant.xz, ji["plant"]["xz"])
    assert same(iff.plant.delay, ji["plant"]["delay_s"])
    # The controller (control.IffControllerParams): rad/s in Python, Hz in results.json.
    c = iff.controller
    assert isinstance(c, pb.control.IffControllerParams) and c.gain == ji["controller"]["gain"]
    assert same(c.w_hpf / (2 * np.pi), ji["controller"]["hpf_Hz"]) and same(c.w_lpf / (2 * np.pi), ji["controller"]["lpf_Hz"])
    assert same(c.w_robust / (2 * np.pi), ji["controller"]["robust_Hz"]) and c["w_hpf"] == c.w_hpf
    np.testing.assert_allclose(iff.relative_pole_distance, ji["relative_pole_distance"], rtol=1e-12)
    np.testing.assert_allclose(iff.relative_pole_distance, abs(iff.model_poles - iff.damped_poles) / abs(iff.model_poles),
                               rtol=1e-12)
    assert iff.warning == ji["warning"] and iff.failed == ji["failed"] and iff.note == ji["note"]
    # The root locus for the plot: the resonance branch passes through the optimal pole.
    res = [b for b in iff.branches if b.resonance_branch]
    assert len(res) == 1 and isinstance(res[0], campaign.IffLocusBranch) and len(res[0].gains) == len(res[0].re_im.x)
    nearest = np.min(abs(res[0].re_im.x + 1j * res[0].re_im.y - iff.optimal_pole))
    assert nearest < 0.05 * abs(iff.optimal_pole)
    # The super element comparison, when the campaign has one.
    if r.superelement is not None:
        se, jse = r.superelement, j["superelement"]
        assert se.dofs == jse["dofs"] and same(se.ga, jse["ga_N_per_V"]) and same(se.gs * 1e-6, jse["gs_V_per_um"])
        np.testing.assert_allclose(se.modes_Hz, jse["modes_Hz"], rtol=1e-12)
    else:
        assert j.get("superelement") is None


def test_missing_campaign_file():
    with pytest.raises(pb.InputError):
        campaign.run("/nonexistent/campaign.toml")


def test_every_declared_result_member_is_reachable_from_python(demo):
    """Each result struct declares its fields once (core/fields.hpp); Python binds them all from the
    declaration: every declared field is an attribute of the struct's class (fields() is that
    declaration), and walking the campaign's results (units, batch, iff, superelement) reaches a value
    for every field of every struct the demo fills."""
    _, _, r = demo
    decl = campaign.declarations()
    assert {"UnitAnalysis", "FrfAnalysis", "StrokeResult", "BatchAnalysis", "QuantitySpread", "BatchOutlier",
            "FrfSimilarity", "FrfSimilarityUnit", "OutlierOptions", "IffStudy", "IffLocusBranch", "IffControllerParams",
            "IffPlantFit", "DelayedSecondOrderFit", "HysteresisFit", "HysteresisModel", "CreepFit",
            "SuperElementComparison", "SuperElementUnitFit"} <= set(decl)
    for name, (cls, fields) in decl.items():
        assert cls.__name__ == name and [f[0] for f in cls.fields()] == fields, name
        missing = [f for f in fields if not hasattr(cls, f)]
        assert not missing, (name, missing)
    by_class = {cls: fields for cls, fields in decl.values()}
    reached = set()

    def walk(obj):
        fields = by_class.get(type(obj))
        if fields is None:
            if isinstance(obj, list):
                for x in obj:
                    walk(x)
            return
        reached.add(type(obj).__name__)
        for f in fields:
            walk(getattr(obj, f))  # every declared member is readable

    for part in (r.units, r.batch, r.iff, r.superelement):
        walk(part)
    assert {"UnitAnalysis", "FrfAnalysis", "StrokeAnalysis", "StaticStiffnessResult", "HysteresisLoop", "DampedPlant",
            "HysteresisFit", "HysteresisModel", "BatchAnalysis", "QuantitySpread", "OutlierOptions", "IffStudy",
            "IffLocusBranch", "IffControllerParams", "IffPlantFit", "DelayedSecondOrderFit"} <= reached
    assert r.units[0].stroke_analysis.result.sensitivity == pytest.approx(
        r.units[0].json()["stroke"]["sensitivity_um_per_V"] * 1e-6, rel=1e-12)


def test_batch_classes_hold_the_batch_figures_recomputed_with_numpy(tmp_path):
    """campaign.BatchAnalysis of three units (unit 3 of the demo has undersized stacks): each spread
    and outlier recomputed with numpy from the units' own SI values, the FRF similarity's maximum."""
    files = campaign.write_demo(str(tmp_path), fast=True, units=[1, 2, 3], iff_gains=[60e3])
    r = campaign.run(files.campaign)
    b = r.batch
    assert isinstance(b, campaign.BatchAnalysis) and isinstance(b.rule, campaign.OutlierOptions)
    values = {"capacitance_sensor_uF": [u.capacitance_sensor * 1e6 for u in r.units],
              "stroke_um": [u.stroke * 1e6 for u in r.units],
              "k1_N_per_um": [u.k1 * 1e-6 for u in r.units],
              "resonance_Hz": [u.resonance_Hz for u in r.units]}
    for q, x in values.items():
        s = b.spread_of(q)
        med = np.median(x)
        assert s.units == 3 and s.min == pytest.approx(min(x), rel=1e-12) and s.max == pytest.approx(max(x), rel=1e-12)
        assert s.median == pytest.approx(med, rel=1e-12)
        assert s.mad == pytest.approx(np.median(np.abs(np.array(x) - med)), rel=1e-9)
        assert s.relative_spread == pytest.approx((max(x) - min(x)) / abs(med), rel=1e-9)
    out = {(o.unit, o.quantity): o for o in b.outliers}
    assert (3, "capacitance_sensor_uF") in out and (3, "stroke_um") in out
    for (unit, q), o in out.items():
        assert isinstance(o, campaign.BatchOutlier) and abs(o.robust_z) > b.rule.threshold
        if q in values:
            s = b.spread_of(q)
            assert o.value == pytest.approx(values[q][unit - 1], rel=1e-12) and o.median == s.median
            assert o.robust_z == pytest.approx(0.6745 * (o.value - s.median) / s.mad, rel=1e-9)
    assert b.rejects and not r.unit(3).accepted and r.unit(1).accepted
    sim = b.similarity
    assert isinstance(sim, campaign.FrfSimilarity) and [s.unit for s in sim.units] == [1, 2, 3]
    assert all(isinstance(s, campaign.FrfSimilarityUnit) for s in sim.units)
    assert sim.max_rms_dB == max(max(s.de_rms_dB, s.vs_rms_dB) for s in sim.units)
    assert sim.fmin_Hz < sim.fmax_Hz
    assert max(sim.units, key=lambda s: s.vs_rms_dB).unit == 3  # the odd unit is the farthest from the median
