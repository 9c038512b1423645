"""The quad mesh in a real finite-element analysis: CalculiX on the exported .inp."""

from __future__ import annotations

from quadcnn_wb.fem.plate_tension import heywood_kt_net, solve


def test_plate_with_hole_peak_stress_matches_the_concentration_factor(tmp_path):
    result = solve(size=2.5, workdir=tmp_path)
    assert abs(result["error"]) < 0.05, result
    assert heywood_kt_net(0.2) == 2.512
    assert (tmp_path / "plate.frd").stat().st_size > 0
