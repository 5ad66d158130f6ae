"""Monte Carlo numbers at the precision of their standard error, and the one-line agreement of
the engines (issue 14)."""

from __future__ import annotations

from paths import EXAMPLES

from langur.cli import main
from langur.commands import _common as c


def test_value_is_rounded_at_the_second_digit_of_its_standard_error():
    assert (c.fmt_mc(3.992450112, 0.0305), c.fmt_se(0.0305)) == ("3.992", "0.030")
    assert (c.fmt_mc(0.499, 0.005), c.fmt_se(0.005)) == ("0.4990", "0.0050")
    assert (c.fmt_mc(1234.5678, 12.3), c.fmt_se(12.3)) == ("1235", "12")
    assert c.fmt_mc(1.0, 0.0) == "1" and c.fmt_se(0.0) == "0"  # exact: no rounding to invent
    assert c.fmt_mc(float("nan"), float("nan")) == "nan"


def test_agreement_counts_standard_errors():
    assert c.agreement(1.0, None, 1.02, 0.025) == "engines agree: |exact − MC| = 0.8 SE"
    assert c.agreement(1.0, None, 1.2, 0.025).startswith("engines DISAGREE: |exact − MC| = 8.0 SE")
    assert c.agreement(1.0, None, 1.0, 0.0).startswith("engines agree: |exact − MC| = 0")
    assert c.agreement(1.0, None, 0.5, 0.0).startswith("engines DISAGREE")
    # a quadrature bound on the exact value widens the band
    assert c.agreement(1.0, 0.1, 1.2, 0.025).startswith("engines agree")


def test_eval_and_deriv_say_whether_the_engines_agree(capsys):
    assert main(["eval", str(EXAMPLES / "fig1.lgr"), "--samples", "4000", "--seed", "2"]) == 0
    out = capsys.readouterr().out
    mc = next(line for line in out.splitlines() if line.strip().startswith("MC"))
    value, se = mc.split(":")[1].split("(")[0].split("±")
    assert len(value.strip().split(".")[1]) == len(se.strip().split(".")[1])  # same decimal place
    k = abs(0.5 - float(value)) / float(se)  # ⟦p⟧ = θ = 1/2 by hand; value and SE as printed (rounded)
    line = next(line for line in out.splitlines() if line.startswith("  agree : engines agree: |exact − MC| = "))
    assert abs(float(line.split("= ")[-1].split(" SE")[0]) - k) < 0.15
    assert main(["deriv", str(EXAMPLES / "fig9.lgr"), "--samples", "4000", "--seed", "2"]) == 0
    out = capsys.readouterr().out
    assert "  agree       : engines agree: |exact − MC| = " in out
