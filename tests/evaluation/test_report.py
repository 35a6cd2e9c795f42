"""occupose.evaluation.report: the tables on hand-made rows."""

import math

import pytest

from occupose.evaluation.errors import TableRow
from occupose.evaluation.report import markdown_table, number_cell, table_i_cells, table_i_markdown


# --------------------------------------------------------------------------- tables


def _row(**changes):
    values = dict(mean_cm=12.0, std_cm=5.0, under10=30.0, under15=60.0, under20=80.0,
                  over20=20.0, fail=False, frames=100, coverage=100.0)
    values.update(changes)
    return TableRow(**values)


def test_markdown_table_rule_follows_the_alignment():
    assert markdown_table(["a", "b", "c"], [["x", "1", "2"]], text_columns=1) == (
        "| a | b | c |\n|---|---:|---:|\n| x | 1 | 2 |")
    assert markdown_table(["a", "b"], [], text_columns=2) == "| a | b |\n|---|---|"
    assert markdown_table(["a", "b"], [["x", "y"]]).splitlines()[1] == "|---|---|"  # no alignment
    with pytest.raises(ValueError, match=r"a row of 2 columns \['a', 'b'\] has 1 cells"):
        markdown_table(["a", "b"], [["x"]])


def test_table_i_cells_and_the_one_line_summary():
    assert table_i_cells(_row()) == ["30.00", "60.00", "80.00", "20.00", "12.00", "5.00", "ok", "100.00"]
    assert table_i_cells(_row(mean_cm=math.nan, fail=True))[4:7] == ["n/a", "5.00", "FAIL"]
    assert number_cell(math.nan) == "n/a" and number_cell(2.345, 1) == "2.3"
    assert "avg 12.00 cm" in _row().format() and "ok" in _row().format()


def test_table_i_markdown_bolds_best_per_group():
    groups = {
        "Seq1": {"OUR": _row(mean_cm=10.0, under10=50.0), "APF": _row(mean_cm=15.0, under10=50.0, std_cm=4.0)},
        "Seq2": {"OUR": _row(over20=math.nan)},
    }
    lines = table_i_markdown(groups).splitlines()
    assert lines[0].startswith("| sequence | method | <10cm [%]")
    our, apf, seq2 = (line.split(" | ") for line in lines[2:5])
    assert our[0] == "| Seq1" and apf[0] == "| " and seq2[0] == "| Seq2"
    assert our[2] == "**50.00**" and apf[2] == "**50.00**"  # tie: both bold
    assert our[6] == "**10.00**" and apf[6] == "15.00"  # lower mean is better
    assert our[7] == "5.00" and apf[7] == "**4.00**"
    assert our[8] == "ok"  # status not ranked
    assert seq2[5] == "n/a" and seq2[6] == "**12.00**"
