"""The report scripts that draw from shipped files run and write their figures."""


def test_the_cad_figure_draws_the_shipped_outlines(tmp_path):
    from bench.reports.cad_figure import PARTS, draw

    png = draw(PARTS, tmp_path)
    assert png.exists() and png.stat().st_size > 10_000
