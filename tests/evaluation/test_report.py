"""occupose.evaluation.report: the tables on hand-made rows."""

import math

from occupose.evaluation.errors import TableRow
from occupose.evaluation.report import format_table, markdown_table


# --------------------------------------------------------------------------- tables


def _row(**changes):
    values = dict(mean_cm=12.0, std_cm=5.0, under10=30.0, under15=60.0, under20=80.0,
                  over20=20.0, fail=False, frames=100, coverage=100.0)
    values.update(changes)
    return TableRow(**values)


def test_format_table_aligned():
    text = format_table({"OUR": _row(), "APF": _row(mean_cm=math.nan, fail=True)})
    lines = text.splitlines()
    assert lines[0].split("  ")[0].strip() == "method"
    for heading in ("<10cm [%]", ">20cm [%]", "Avg Err [cm]", "Std Dev [cm]", "Status"):
        assert heading in lines[0]
    assert len({len(line) for line in lines}) == 1  # right-aligned last column
    assert "12.00" in lines[1] and "ok" in lines[1]
    assert "n/a" in lines[2] and "FAIL" in lines[2]
    assert "avg 12.00 cm" in _row().format() and "ok" in _row().format()


def test_markdown_table_bolds_best_per_group():
    groups = {
        "Seq1": {"OUR": _row(mean_cm=10.0, under10=50.0), "APF": _row(mean_cm=15.0, under10=50.0, std_cm=4.0)},
        "Seq2": {"OUR": _row(over20=math.nan)},
    }
    lines = markdown_table(groups).splitlines()
    assert lines[0].startswith("| sequence | method | <10cm [%]")
    our, apf, seq2 = (line.split(" | ") for line in lines[2:5])
    assert our[0] == "| Seq1" and apf[0] == "| " and seq2[0] == "| Seq2"
    assert our[2] == "**50.00**" and apf[2] == "**50.00**"  # tie: both bold
    assert our[6] == "**10.00**" and apf[6] == "15.00"  # lower mean is better
    assert our[7] == "5.00" and apf[7] == "**4.00**"
    assert our[8] == "ok"  # status not ranked
    assert seq2[5] == "n/a" and seq2[6] == "**12.00**"
