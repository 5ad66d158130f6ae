"""A small engine in another process, speaking the line protocol of docs/engines.md: it reads the
program as langur-core JSON and answers with the workbench's Monte Carlo engine, a stochastic
engine with its standard error (so it should agree with the exact engine), or misbehaves on purpose: ``--crash`` exits on the first question, ``--hang`` never answers,
``--garbage`` answers something that is not JSON, ``--decline`` declines everything,
``--wrong`` adds 1 to every answer.  Used by proofs_tests/test_engines.py."""

import json
import sys
import time

mode = sys.argv[1] if len(sys.argv) > 1 else ""
for line in sys.stdin:
    ask = json.loads(line)
    # the misbehaviours come before the workbench is imported: they happen at once, however long a
    # loaded machine takes to import it (bench/history/2026-11-29.md#flake32
    if mode == "--crash":
        sys.exit(3)
    if mode == "--hang":
        time.sleep(3600)
    if mode == "--garbage":
        print("this is not an answer", flush=True)
        continue
    if mode == "--decline":
        print(json.dumps({"id": ask["id"], "declined": "this engine declines everything"}), flush=True)
        continue
    from langur import core_json, operational

    program, _ = core_json.from_json(ask["program"])
    if ask["request"] == "value":
        r = operational.estimate_value(program, ask["params"], samples=20000, seed=ask["id"])
    else:
        r = operational.estimate_derivative(program, ask["params"], ask["direction"], samples=20000, seed=ask["id"])
    value = r.value + (1.0 if mode == "--wrong" else 0.0)
    print(json.dumps({"id": ask["id"], "kind": "stochastic", "value": value, "error": r.stderr}), flush=True)
