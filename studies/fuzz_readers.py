"""Fuzz every reader of files written elsewhere (issue 80): N corrupted variants of a valid
sample per format (tests/fuzz_readers.py says how a case is made), each read through the entry
points a user's command reaches; a case passes when it is read or refused in one
DceeInputError line, and fails on any other exception, a message of several lines or no answer
within 30 s. Declared sizes above 256 MiB are refused under the fuzz (DCEE_MAX_ARRAY_BYTES).

    python studies/fuzz_readers.py --cases 1000 --json docs/results/fuzz/readers.json
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", type=int, default=1000, help="cases per format")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--formats", help="comma-separated names (default: every format)")
    ap.add_argument("--json", help="write the outcome here")
    args = ap.parse_args(argv)

    from tests.fuzz_readers import FORMATS, FUZZ_ARRAY_LIMIT, fuzz_environment, run_format

    from dcee.perf.machine import machine_record
    from dcee.provenance import code_version

    fuzz_environment()
    names = args.formats.split(",") if args.formats else list(FORMATS)
    rows = []
    for k, name in enumerate(names):
        with tempfile.TemporaryDirectory() as scratch:
            outcome, seconds = run_format(name, args.cases, args.seed + k, Path(scratch))
        rows.append(
            {
                "format": name,
                "cases": args.cases,
                "read": outcome.read,
                "refused": outcome.refused,
                "failures": outcome.failures,
                "seconds": round(seconds, 1),
            }
        )
        print(
            f"{name:16s} {args.cases} cases: {outcome.read} read, {outcome.refused} refused, "
            f"{len(outcome.failures)} failed ({seconds:.0f} s)",
            flush=True,
        )
        for failure in outcome.failures[:10]:
            print(f"    {failure}", flush=True)
    if args.json:
        doc = {
            "code_version": code_version(),
            "machine": machine_record(),
            "seed": args.seed,
            "array_limit_bytes": int(FUZZ_ARRAY_LIMIT),
            "formats": rows,
        }
        out = Path(args.json)
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(json.dumps(doc, indent=2) + "\n", encoding="utf-8")
    return 1 if any(r["failures"] for r in rows) else 0


if __name__ == "__main__":
    raise SystemExit(main())
