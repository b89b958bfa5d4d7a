"""The demo section `elastica` (Fig. 4 and Fig. 5 style figures on bundled data)."""

import pytest

from curvesmith import demo


def test_elastica_demo_section(tmp_path, monkeypatch):
    if "elastica" not in demo.SECTIONS:
        monkeypatch.setattr(demo, "SECTIONS", [*demo.SECTIONS, "elastica"])
    summary = demo.run_demo(tmp_path, sections=["elastica"])
    (section,) = summary["sections"]
    for figure in section["figures"]:
        assert (tmp_path / figure["file"]).stat().st_size > 20_000
    assert len(section["figures"]) == 4  # + the multi-segment fair (issue 11, part 5)
    numbers = {key: entry["value"] for key, entry in section["numbers"].items()}
    # bundled data: true k 0.75, 1.25, 0.9 (PROVENANCE_elastica.md); noise 0.02, 0.01, 0.005
    assert numbers["elastica_wave_success"] and numbers["elastica_loop_success"]
    assert numbers["elastica_digitised_success"]
    assert numbers["elastica_wave_k"] == pytest.approx(0.75, abs=0.01)
    assert numbers["elastica_loop_k"] == pytest.approx(1.25, abs=0.01)
    assert numbers["elastica_digitised_k"] == pytest.approx(0.9, abs=0.01)
    assert numbers["elastica_wave_rms"] < 0.02 * 1.5
    assert numbers["elastica_figure_eight_k"] == pytest.approx(0.9189, abs=1e-4)
    # three G1 pieces, 0.02 mm noise, T = 0.08 mm: three segments, joints to 2 vertices (4 mm)
    assert numbers["elastica_segments_count"] == 3
    assert numbers["elastica_segments_max_deviation"] <= 0.08
    assert 0 <= numbers["elastica_segments_joint_error"] <= 4.0
    assert numbers["elastica_segments_g1_defect"] < 1e-9
