"""The exact engine's answers per program of a fixed list, with the CPU spent in Theorem 8.1's
finite differences (issue 13, campaign7): where a campaign's later programs spend their time.

    python bench/bench_campaign_fd.py LIST.json OUT.json [--only 20,49]

``LIST.json``: a JSON list of program texts (e.g. ``langur.fuzz.compare.generated(1000, 1)[300:700:5]``
saved once).  For each program, in this process and one after the other, the campaign's exact
answers (``langur.fuzz.compare._exact_answers``: the value and every partial derivative with its
Theorem 8.1 check, the closed-form search bounded as in a campaign), timed in CPU seconds
(``time.process_time``), and the CPU of ``theorem._finite_difference`` within them.  ``OUT.json``
keeps each answer (value, error, method; the check's verdict, how, D⟦p⟧·γ' and bound), so that two
versions of the code (``PYTHONPATH=TREE python -P TREE/bench/bench_campaign_fd.py``), run side by
side, can be compared answer by answer.  Prints one line per program and the totals.
"""

from __future__ import annotations

import argparse
import json
import time

from langur import theorem
from langur.frontend import load_text
from langur.fuzz import compare


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("programs")
    ap.add_argument("out")
    ap.add_argument("--only", help="comma-separated positions in the list")
    a = ap.parse_args()
    texts = json.load(open(a.programs))
    chosen = range(len(texts)) if not a.only else [int(i) for i in a.only.split(",")]
    fd = {"cpu": 0.0, "calls": 0}
    real = theorem._finite_difference

    def timed(*args, **kwargs):
        c0 = time.process_time()
        try:
            return real(*args, **kwargs)
        finally:
            fd["cpu"] += time.process_time() - c0
            fd["calls"] += 1

    theorem._finite_difference = timed
    rows = []
    for i in chosen:
        loaded = load_text(texts[i], path="<fuzz>.lgr")
        fd.update(cpu=0.0, calls=0)
        c0 = time.process_time()
        status, ex, exd, _ = compare._exact_answers(loaded.program, loaded.param_values({}), 20.0)
        row = {"i": i, "cpu": round(time.process_time() - c0, 3), "fd_cpu": round(fd["cpu"], 3),
               "fd_calls": fd["calls"], "status": status}
        if status == "ok":
            row["value"] = [ex.value, ex.error, str(ex.method)]
            row["d"] = {p: [r.value, r.error, str(r.method)] for p, r in exd.items()}
            row["th"] = {p: None if r.theorem_8_1 is None else
                         [r.theorem_8_1.holds, str(r.theorem_8_1.how), r.theorem_8_1.d_denotation, r.theorem_8_1.error]
                         for p, r in exd.items()}
        rows.append(row)
        print(i, row["cpu"], row["fd_cpu"], row["fd_calls"], status, flush=True)
    with open(a.out, "w") as f:
        json.dump(rows, f)
    print(f"{len(rows)} programs: exact engine {sum(r['cpu'] for r in rows):.1f} CPU s, of which Theorem 8.1's "
          f"finite differences {sum(r['fd_cpu'] for r in rows):.1f} s ({sum(r['fd_calls'] for r in rows)} checks)")


if __name__ == "__main__":
    main()
