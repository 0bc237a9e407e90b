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
    assert len(r.batch.outliers) == len(j["batch"]["outliers"])
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


def test_missing_campaign_file():
    with pytest.raises(pb.InputError):
        campaign.run("/nonexistent/campaign.toml")


def test_every_declared_result_member_is_reachable_from_python(demo):
    """Each result struct declares its fields once (core/fields.hpp); Python binds them all from the
    declaration: every declared field is an attribute of the struct's class, and walking a unit's
    results reaches a value for every field of every struct the demo fills."""
    _, _, r = demo
    decl = campaign.declarations()
    assert "UnitAnalysis" in decl and "FrfAnalysis" in decl and "StrokeResult" in decl
    for name, (cls, fields) in decl.items():
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

    walk(r.units[0])
    assert {"UnitAnalysis", "FrfAnalysis", "StrokeAnalysis", "StaticStiffnessResult", "HysteresisLoop", "DampedPlant"} <= reached
    assert r.units[0].stroke_analysis.result.sensitivity == pytest.approx(
        r.units[0].json()["stroke"]["sensitivity_um_per_V"] * 1e-6, rel=1e-12)
