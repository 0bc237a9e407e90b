"""piezobench.campaign: a short demo campaign written and run from Python, its typed results
checked against the virtual bench's truth (as tests/campaign/demo_test.cpp does in C++)."""

import json

import pytest

import piezobench as pb
from piezobench import campaign


def test_demo_campaign_results_agree_with_the_truth(tmp_path):
    files = campaign.write_demo(str(tmp_path), fast=True, units=[1], iff_gains=[60e3, 120e3])
    r = campaign.run(files.campaign, out_dir=str(tmp_path / "out"))
    truth = json.loads(open(files.truth).read())["units"][0]
    unit = r.results.units[0]
    assert unit.id == 1 and unit.accepted and r.accepted == 1 and r.rejected == 0
    assert unit.frf.resonance_Hz == pytest.approx(truth["resonance_Hz"], rel=0.01)
    assert unit.frf.antiresonance_Hz == pytest.approx(truth["antiresonance_Hz"], rel=0.01)
    assert unit.frf.zero_is_nonminimum_phase == truth["zero_is_nonminimum_phase"]
    assert unit.stiffness_N_per_um.k1 == pytest.approx(truth["stiffness_N_per_um"]["k1"], rel=0.05)
    # to_dict() is plain data: the same document as results.json on disk.
    d = r.results.to_dict()
    on_disk = json.loads((tmp_path / "out" / "results.json").read_text())
    assert d["units"][0]["id"] == on_disk["units"][0]["id"]
    assert d["units"][0]["frf"]["resonance_Hz"] == pytest.approx(on_disk["units"][0]["frf"]["resonance_Hz"], rel=1e-12)
    assert any(p.endswith("report.html") for p in r.written)


def test_missing_campaign_file():
    with pytest.raises(pb.InputError):
        campaign.run("/nonexistent/campaign.toml")
